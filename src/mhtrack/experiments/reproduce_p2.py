"""Reproduce P2 (Gong, Dai & Ma 2013): the θ sweeps of Figs. 3–4, Figs. 2 and 12–15,
Tables 1–2, on the ``multiradar`` preset (``docs/initiation.md``).

The code lives in the package :mod:`mhtrack.experiments.p2`, one concept per module (its
docstring lists them): :mod:`~mhtrack.experiments.p2.jobs` describes the jobs and the
seeding, :mod:`~mhtrack.experiments.p2.study` the entry point :func:`reproduce_p2` and
its outputs. This module re-exports every name it defined (or imported) before the split,
so ``from mhtrack.experiments.reproduce_p2 import ...`` keeps working. Study directories
written before the split resume as before: a job's hash and its file hold only the job's
parameters, no module path.
"""

# ruff: noqa: F401  (re-exports)

from __future__ import annotations

import hashlib
import json
import math
import os
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.experiments.montecarlo import atomic_write, execute
from mhtrack.experiments.p2.aggregate import _nan, _ratio, aggregate, curve_for
from mhtrack.experiments.p2.constants import (
    CHUNK,
    CLUSTER_LABELS,
    FIGURES,
    JOBS_DIR,
    LOGIC_PARAMS,
    METHOD_LABELS,
    PAPER_COMPLEXITY,
    PAPER_T_CLUSTER,
    PAPER_T_INIT,
    RATE0,
    RATES,
    REPORT_FILE,
    RESULTS_FILE,
    SIGMA0,
    SIGMAS,
    TABLES_FILE,
    THETA0,
    THETAS_DEG,
)
from mhtrack.experiments.p2.figures import _clustering_figure, _curve_figure, _tracks_figure
from mhtrack.experiments.p2.jobs import (
    JOB_FUNCTIONS,
    _done,
    _hash,
    _initiable,
    _initiators,
    _score,
    _seed_of,
    clustering_job,
    grid_job,
    make_jobs,
    methods_job,
    p2_scenario,
    run_job,
    run_jobs,
)
from mhtrack.experiments.p2.report import (
    _f,
    _ms,
    _speed_ratio,
    comparison_text,
    report_markdown,
    tables_markdown,
)
from mhtrack.experiments.p2.study import P2Reproduction, _jsonable, reproduce_p2
from mhtrack.initiation import INITIATORS, Window, make_initiator
from mhtrack.initiation.logic import sweep_modified_logic
from mhtrack.initiation.runs import fuse, fused_scans, n_targets_seen, run_seeds
from mhtrack.initiation.window import sliding_windows
from mhtrack.metrics.initiation import initiable_targets, track_targets
from mhtrack.scenario import Scenario, preset, simulate
