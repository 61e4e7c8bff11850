"""The records of a Monte-Carlo study and their summary: per tracker and scalar metric,
mean and population standard deviation (``ddof=0``) over the successful runs, ignoring
NaN; per scan, the mean ± std of OSPA, GOSPA and cardinality over runs."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.experiments.jobs import JobStore
from mhtrack.experiments.montecarlo.job import RECORDS
from mhtrack.experiments.montecarlo.spec import RUNS_DIR, SPEC_FILE, MonteCarloSpec

#: Scalar columns that are the evaluation's parameters (the same in every run), reported
#: under ``parameters``, not averaged among the metrics.
PARAMETERS: tuple[str, ...] = ("cutoff", "order", "match_distance", "ospa2_window",
                                "hota_distance")
#: Scalar columns that are bookkeeping or parameters, not metrics.
NOT_METRICS = frozenset({"run", "seed", "base_seed", *PARAMETERS})


def run_store(out_dir: str | os.PathLike[str]) -> JobStore:
    """The job store of a study directory: ``runs/<tracker>/run-<i>.parquet``."""
    return JobStore(Path(out_dir) / RUNS_DIR, RECORDS, check=check_run_record)


def check_run_record(job: Any, record: Mapping[str, Any]) -> None:
    """A run file read back has what the summary reads: its ``run``, the ``scans`` and a
    per-scan list of each per-scan metric as long (or null); raises
    ``ValueError("<field>: <problem>")`` (named with the file by the store)."""
    run = record.get("run")
    if run != job.params["run"]:
        raise ValueError(f"run: expected {job.params['run']}, got {run!r}")
    scans = record.get("scans")
    if not isinstance(scans, list) or not all(
            isinstance(k, int | float) and not isinstance(k, bool) for k in scans):
        raise ValueError(f"scans: expected a list of scan numbers, got {type(scans).__name__}")
    for key in ("ospa", "gospa", "cardinality", "cardinality_true"):
        v = record.get(key)
        if v is not None and (not isinstance(v, list) or len(v) != len(scans)):
            got = f"a list of {len(v)}" if isinstance(v, list) else type(v).__name__
            raise ValueError(f"{key}: expected a list of {len(scans)} values (one per scan), "
                             f"got {got}")
    caps = record.get("caps")
    if caps is not None:
        try:
            ok = isinstance(json.loads(caps), dict)
        except (TypeError, ValueError, RecursionError):
            ok = False
        if not ok:
            raise ValueError(f"caps: expected a JSON object as text, got {caps!r:.60}")


@dataclass
class MonteCarloResult:
    """Records of a study: ``records[tracker]`` the successful runs (sorted by run),
    ``failures[tracker][run]`` the traceback of each failed run, ``missing`` jobs with
    neither; ``computed`` / ``skipped`` count this call's jobs (0 from :func:`load_results`)."""

    spec: MonteCarloSpec
    out_dir: Path
    records: dict[str, list[dict[str, Any]]]
    failures: dict[str, dict[int, str]]
    missing: list[tuple[str, int]] = field(default_factory=list)
    computed: int = 0
    skipped: int = 0

    def runs_with_caps(self) -> dict[str, int]:
        """Per tracker, the number of successful runs in which a hard cap of the MHT acted."""
        return {t: sum(1 for r in recs if json.loads(r.get("caps") or "{}"))
                for t, recs in self.records.items()}

    def caps_per_run(self) -> dict[str, list[dict[str, Any]]]:
        """Per tracker, each successful run's hard caps: ``{"run", "scans", <cap>: count}``
        (``scans``: scans at which any cap acted; a cap's count: what it cut over the
        run); ``{"run": i, "scans": 0}`` for a run no cap touched."""
        out: dict[str, list[dict[str, Any]]] = {}
        for t, recs in self.records.items():
            rows = []
            for r in recs:
                caps = json.loads(r.get("caps") or "{}")
                scans = caps.pop("scans", None)
                if scans is None:  # runs stored before the count of scans existed
                    scans = len({k for v in json.loads(r.get("cap_scans") or "{}").values()
                                 for k in v})
                rows.append({"run": int(r["run"]), "scans": int(scans), **caps})
            out[t] = rows
        return out

    @property
    def ok(self) -> bool:
        return not any(self.failures.values()) and not self.missing

    def metric_keys(self) -> list[str]:
        """Numeric scalar columns, in first-seen order."""
        keys: dict[str, None] = {}
        for recs in self.records.values():
            for r in recs:
                for k, v in r.items():
                    if (k not in NOT_METRICS and not isinstance(v, bool | str | list)
                            and isinstance(v, int | float)):
                        keys.setdefault(k)
        return list(keys)

    def parameters(self, tracker: str) -> dict[str, Any]:
        """The evaluation's :data:`PARAMETERS` of ``tracker``'s runs (OSPA/GOSPA cut-off
        ``c`` and order ``p``, CLEAR-MOT matching distance): one value when every run has
        the same, else the sorted list of values."""
        out: dict[str, Any] = {}
        for k in PARAMETERS:
            vals = sorted({r[k] for r in self.records.get(tracker, []) if r.get(k) is not None})
            if vals:
                out[k] = vals[0] if len(vals) == 1 else vals
        return out

    def summary(self) -> dict[str, dict[str, Any]]:
        """``{tracker: {metric: mean, …, "std": {metric: std}, "n_runs", "failed",
        "parameters": {cutoff, order, match_distance}, "per_scan": {scans, ospa, ospa_std,
        cardinality, cardinality_std, cardinality_true, gospa, gospa_std}}}`` — means
        under the ``evaluate`` keys plus ``t_avg``; NaN where no run has a value. The
        evaluation's parameters are under ``parameters`` (:meth:`parameters`), not among
        the metrics."""
        keys = self.metric_keys()
        out: dict[str, dict[str, Any]] = {}
        for t in self.spec.trackers:
            recs = self.records.get(t, [])
            entry: dict[str, Any] = {}
            std: dict[str, float] = {}
            for k in keys:
                vals = np.array([_num(r.get(k)) for r in recs], float)
                entry[k], std[k] = mean_std(vals)
            entry["std"] = std
            entry["n_runs"] = len(recs)
            entry["failed"] = sorted(self.failures.get(t, {}))
            entry["parameters"] = self.parameters(t)
            entry["per_scan"] = per_scan(recs)
            out[t] = entry
        return out


def _num(v: Any) -> float:
    return math.nan if v is None else float(v)


def mean_std(vals: np.ndarray) -> tuple[float, float]:
    """Mean and population std (``ddof=0``) of the finite values; NaN, NaN if none."""
    vals = vals[np.isfinite(vals)]
    if vals.size == 0:
        return math.nan, math.nan
    return float(vals.mean()), float(vals.std())


def per_scan(recs: Sequence[Mapping[str, Any]]) -> dict[str, list[float]]:
    """Per-scan mean ± std over runs, aligned on scan index (a scan missing from a run
    does not count for it)."""
    scans = sorted({int(k) for r in recs for k in r.get("scans") or []})
    pos = {k: j for j, k in enumerate(scans)}
    out: dict[str, list[float]] = {"scans": scans}
    for key in ("ospa", "gospa", "cardinality", "cardinality_true"):
        a = np.full((len(recs), len(scans)), np.nan)
        for i, r in enumerate(recs):
            if r.get(key) is None:
                continue
            for k, v in zip(r["scans"], r[key], strict=True):
                a[i, pos[int(k)]] = np.nan if v is None else v
        mean = np.full(len(scans), np.nan)
        std = np.full(len(scans), np.nan)
        for j in range(len(scans)):
            mean[j], std[j] = mean_std(a[:, j])
        out[key] = mean.tolist()
        if key != "cardinality_true":
            out[f"{key}_std"] = std.tolist()
    return out


def load_results(out_dir: str | os.PathLike[str]) -> MonteCarloResult:
    """Read a study directory: its spec, its run files and its error files."""
    out_dir = Path(out_dir)
    path = out_dir / SPEC_FILE
    if not path.is_file():
        raise FileNotFoundError(f"{out_dir}: no {SPEC_FILE}; not a Monte-Carlo directory")
    spec = MonteCarloSpec.from_file(path)
    store = run_store(out_dir)
    records: dict[str, list[dict[str, Any]]] = {t: [] for t in spec.trackers}
    failures: dict[str, dict[int, str]] = {t: {} for t in spec.trackers}
    missing: list[tuple[str, int]] = []
    for job in spec.jobs():
        t, i = job.params["tracker"], job.params["run"]
        if store.is_done(job):
            records[t].append(store.load(job))
        elif (error := store.error(job)) is not None:
            failures[t][i] = error
        else:
            missing.append((t, i))
    for t in spec.trackers:
        records[t].sort(key=lambda r: r["run"])
    return MonteCarloResult(spec, out_dir, records, failures, missing)
