"""Entry point of the P2 (Gong, Dai & Ma 2013, multi-radar track initiation) reproduction:
:func:`reproduce_p2` runs (or resumes) the study's jobs (:mod:`mhtrack.experiments.p2.jobs`)
into ``DIR/jobs/`` and aggregates them; :class:`P2Reproduction` is what it returns. The
outputs (``results.json``, ``tables.md``, ``report.md``, the figures) are written by
:func:`mhtrack.reports.p2.write_p2_report`.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mhtrack.experiments.jobs import JobStore, run_jobs
from mhtrack.experiments.p2.aggregate import aggregate
from mhtrack.experiments.p2.constants import (
    CHUNK,
    CLUTTER_PER,
    JOBS_DIR,
    PAPER_COMPLEXITY,
    PAPER_T_CLUSTER,
    PAPER_T_INIT,
    RATES,
    SETTINGS,
    SIGMAS,
    THETAS_DEG,
)
from mhtrack.experiments.p2.jobs import STORE_FORMAT, check_record, make_jobs, run_job
from mhtrack.io.jsonsafe import to_jsonable


@dataclass
class P2Reproduction:
    """The aggregated ``results`` (JSON data, non-finite numbers as ``None``), the job
    counts of this call, the traceback of each failed job (by name) and the wall time of
    the jobs computed now."""

    out_dir: Path
    runs: int
    seed: int
    results: dict[str, Any]
    computed: int
    skipped: int
    errors: dict[str, str] = field(default_factory=dict)
    wall_seconds: float = 0.0


def reproduce_p2(out_dir: str | os.PathLike[str], runs: int = 10, seed: int = 0, *,
                 thetas: Sequence[float] | None = None, sigmas: Sequence[float] | None = None,
                 rates: Sequence[float] | None = None, executor: str = "local",
                 workers: int | None = None, scheduler: Any = None, progress: bool = False,
                 chunk: int = CHUNK, settings: str = "best",
                 clutter_per: str = "radar") -> P2Reproduction:
    """Run (or resume) the P2 study into ``out_dir/jobs/`` and aggregate it. ``thetas``
    (deg), ``sigmas`` (m) and ``rates`` default to P2's grids; ``settings`` ``"best"``
    (ours) or ``"paper"`` (P2's steps only); ``clutter_per`` ``"radar"`` (λ per radar per
    scan) or ``"scan"`` (λ per scan over all radars) — :mod:`~mhtrack.experiments.p2.constants`."""
    if settings not in SETTINGS:
        raise ValueError(f"settings must be one of {', '.join(SETTINGS)}, got {settings!r}")
    if clutter_per not in CLUTTER_PER:
        raise ValueError(f"clutter_per must be one of {', '.join(CLUTTER_PER)}, "
                         f"got {clutter_per!r}")
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    if seed < 0:
        raise ValueError(f"seed must be >= 0, got {seed}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    thetas = list(THETAS_DEG if thetas is None else thetas)
    if not all(0 <= x <= 180 for x in thetas):
        raise ValueError("thetas must be in [0, 180] degrees")
    jobs = make_jobs(runs, seed, thetas, SIGMAS if sigmas is None else sigmas,
                     RATES if rates is None else rates, chunk, settings=settings,
                     clutter_per=clutter_per)
    store = JobStore(out / JOBS_DIR, STORE_FORMAT, check=check_record)
    t0 = time.perf_counter()
    done = run_jobs(jobs, run_job, store, executor=executor, workers=workers,
                    scheduler=scheduler, progress=progress, desc="reproduce p2")
    wall = time.perf_counter() - t0
    results = {j.key: store.load(j) for j in jobs if store.is_done(j)}
    res = aggregate([j.params for j in jobs], results, thetas)
    res.update(runs=runs, seed=seed, paper={"t_cluster": PAPER_T_CLUSTER,
                                            "t_init": PAPER_T_INIT,
                                            "complexity": PAPER_COMPLEXITY},
               jobs={"total": len(jobs), "computed": done.computed,
                     "failed": sorted(done.errors)})
    if settings != "best" or clutter_per != "radar":
        res.update(settings=settings, clutter_per=clutter_per)
    return P2Reproduction(out, runs, seed, to_jsonable(res), done.computed, done.skipped,
                          done.errors, wall)
