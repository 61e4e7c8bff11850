"""One Monte-Carlo job: one tracker on one simulated run, reduced to a flat record."""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from typing import Any

import numpy as np

from mhtrack.experiments.jobs import ParquetRecords
from mhtrack.io.jsonsafe import to_jsonable

#: Per-scan list columns of a run record.
PER_SCAN_KEYS = ("scans", "ospa", "gospa", "cardinality", "cardinality_true")
INT_LISTS = frozenset({"scans", "cardinality", "cardinality_true"})
#: How a run record is stored: ``runs/<tracker>/run-<i>.parquet``, one row.
RECORDS = ParquetRecords(int_lists=INT_LISTS, keep_none=frozenset(PER_SCAN_KEYS))


def run_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """Run one job (the dict of :meth:`MonteCarloSpec.job`) and return its record: every
    scalar of :meth:`~mhtrack.experiments.pipeline.ScenarioRun.summary` plus ``tracker``,
    ``run``, ``seed``, ``base_seed``, ``scenario``, ``job_hash``, mappings such as ``caps``
    as JSON text, and the per-scan lists :data:`PER_SCAN_KEYS`. Plain data only."""
    from mhtrack.build import config_with, default_config
    from mhtrack.experiments.pipeline import run_scenario
    from mhtrack.scenario import Scenario

    scenario = Scenario.from_dict(job["scenario"])
    config = config_with(default_config(scenario), **job["config"])
    # Every job builds a new tracker, whose first-time cap warnings would repeat for every
    # run; the caps that acted are kept in the record (``caps``) and counted per tracker
    # by :meth:`MonteCarloResult.runs_with_caps` instead.
    tracker_log = logging.getLogger("mhtrack.mht.tracker")
    level = tracker_log.level
    tracker_log.setLevel(logging.ERROR)
    try:
        result = run_scenario(scenario, job["seed"], job["tracker"], config,
                              **job["run_kwargs"])
    finally:
        tracker_log.setLevel(level)
    summary = result.summary()
    record: dict[str, Any] = {
        "tracker": job["tracker"],
        "run": job["run"],
        "seed": job["seed"],
        "base_seed": job["base_seed"],
        "scenario": scenario.name,
        "job_hash": job["job_hash"],
    }
    for k, v in summary.items():
        if k in record or k in PER_SCAN_KEYS:
            continue
        if v is None or isinstance(v, bool | int | float | str | np.integer | np.floating):
            record[k] = v.item() if isinstance(v, np.generic) else v
        elif isinstance(v, Mapping):
            record[k] = json.dumps(to_jsonable(v, strict=True, nonfinite_as_null=False),
                                   sort_keys=True)
    for k in PER_SCAN_KEYS:
        if k in summary:
            record[k] = [int(x) if k in INT_LISTS else float(x) for x in summary[k]]
    return record
