"""Monte-Carlo studies: many simulated runs of several trackers, on local processes or Dask.

A study (:class:`MonteCarloSpec`) is a scenario, a list of trackers, a number of runs and a
base seed, plus the tracker configuration and keywords forwarded verbatim to
:func:`~mhtrack.experiments.pipeline.run_scenario`. It is cut into one *job* per
``(tracker, run)``:

* **Seeding** — run ``i`` simulates with :func:`run_seed` ``(seed, i)``, derived from the
  base seed and ``i`` only (``np.random.SeedSequence(seed, spawn_key=(i,))``, i.e. child
  ``i`` of ``SeedSequence(seed).spawn(...)``, as a 63-bit integer). Every tracker thus sees
  the same plots in run ``i``, and no result depends on the number of workers, the
  executor or the order in which jobs finish.
* **Files** — ``DIR/montecarlo.json`` holds the full spec (written first);
  each finished job is written at once, atomically (temporary name, then ``os.replace``),
  to ``DIR/runs/<tracker>/run-<i>.parquet``: one row with every scalar of
  :meth:`~mhtrack.experiments.pipeline.ScenarioRun.summary` plus ``run``, ``seed``,
  ``base_seed``, ``scenario``, ``job_hash``, ``caps`` (JSON text), and the per-scan lists
  ``scans``, ``ospa``, ``gospa``, ``cardinality``, ``cardinality_true``. A job that raises
  leaves ``run-<i>.error.txt`` (its traceback) instead; the others go on.
* **Resume** — a rerun skips every job whose Parquet file exists and whose stored
  ``job_hash`` (SHA-256 of the job's full parameters) matches. A directory whose
  ``montecarlo.json`` has another scenario, seed, config or run keywords is refused with
  :class:`SpecMismatchError`; ``trackers`` and ``runs`` may change (adding runs or trackers
  extends a study, since run ``i`` is the same job whatever the number of runs).
* **Summary** — per tracker and scalar metric, mean and population standard deviation
  (``ddof=0``) over the successful runs, ignoring NaN; per-scan OSPA and cardinality
  mean ± std for plotting.

The job function :func:`run_job` is a top-level function of plain data, so it pickles to
a :class:`~concurrent.futures.ProcessPoolExecutor` or a Dask cluster alike.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import logging
import math
import os
import sys
import tempfile
import traceback
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from tqdm.auto import tqdm

#: Bumped when the meaning of a job (and so its hash) changes.
JOB_FORMAT = 2  # 2: run_scenario's history output (mhtrack.mht.history)
SPEC_FILE = "montecarlo.json"
SUMMARY_FILE = "summary.md"
FIGURE_FILE = "ospa_cardinality.png"

#: Spec fields that must match for a directory to be resumed.
STUDY_FIELDS = ("scenario", "seed", "config", "run_kwargs")
#: Per-scan list columns of a run file.
PER_SCAN_KEYS = ("scans", "ospa", "gospa", "cardinality", "cardinality_true")
_INT_LISTS = {"scans", "cardinality", "cardinality_true"}
#: ``run_scenario`` arguments the runner sets itself.
_RESERVED_KWARGS = {"scenario", "seed", "tracker", "config", "progress"}
#: Scalar columns that are bookkeeping, not metrics.
_NOT_METRICS = {"run", "seed", "base_seed"}


class SpecMismatchError(ValueError):
    """The output directory holds runs of a study with other parameters."""


# ---------------------------------------------------------------------------- spec
def _plain(obj: Any) -> Any:
    """JSON round trip: tuples become lists, numpy scalars plain numbers; checks the
    object is JSON data."""
    def default(o: Any) -> Any:
        if isinstance(o, np.integer):
            return int(o)
        if isinstance(o, np.floating):
            return float(o)
        if isinstance(o, np.ndarray):
            return o.tolist()
        raise TypeError(f"not JSON data: {type(o).__name__}")

    return json.loads(json.dumps(obj, default=default))


def _canonical(obj: Any) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"))


def run_seed(seed: int, run: int) -> int:
    """Simulation seed of run ``run`` of a study with base seed ``seed``.

    ``SeedSequence(seed, spawn_key=(run,))`` — child ``run`` of
    ``SeedSequence(seed).spawn(n)`` for any ``n > run`` — reduced to 63 bits. It depends on
    ``seed`` and ``run`` only.
    """
    ss = np.random.SeedSequence(int(seed), spawn_key=(int(run),))
    return int(ss.generate_state(1, np.uint64)[0] >> np.uint64(1))


@dataclass(frozen=True)
class MonteCarloSpec:
    """A Monte-Carlo study.

    Parameters
    ----------
    scenario : Scenario or its dict form (:meth:`Scenario.to_dict`); stored as the dict.
    trackers : tracker names (:data:`~mhtrack.experiments.pipeline.TRACKERS`).
    runs : number of runs per tracker.
    seed : base seed; run ``i`` simulates with :func:`run_seed` ``(seed, i)``.
    config : :class:`~mhtrack.mht.MHTConfig` fields to change from their defaults.
    run_kwargs : further keywords of :func:`~mhtrack.experiments.pipeline.run_scenario`
        (``clutter_density``, ``cutoff``, ``order``, …), forwarded verbatim; JSON data.
    """

    scenario: Mapping[str, Any]
    trackers: tuple[str, ...] = ("mht", "mht-gmm", "mht-agmm")
    runs: int = 10
    seed: int = 0
    config: Mapping[str, Any] = field(default_factory=dict)
    run_kwargs: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        from mhtrack.experiments.pipeline import TRACKERS
        from mhtrack.mht import MHTConfig
        from mhtrack.scenario import Scenario

        sc = self.scenario
        if isinstance(sc, Scenario):
            sc = sc.to_dict()
        elif not isinstance(sc, Mapping):
            raise ValueError(f"scenario: expected a Scenario or its dict, got {type(sc).__name__}")
        trackers = (self.trackers,) if isinstance(self.trackers, str) else tuple(self.trackers)
        if not trackers:
            raise ValueError("trackers: give at least one tracker")
        for t in trackers:
            if t not in TRACKERS:
                raise ValueError(f"unknown tracker {t!r} (expected one of {', '.join(TRACKERS)})")
        if len(set(trackers)) != len(trackers):
            raise ValueError(f"trackers: repeated name in {list(trackers)}")
        for name, v, lo in (("runs", self.runs, 1), ("seed", self.seed, 0)):
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < lo:
                raise ValueError(f"{name}: expected an integer >= {lo}, got {v!r}")
        fields = {f.name for f in dataclasses.fields(MHTConfig)}
        bad = sorted(set(self.config) - fields)
        if bad:
            raise ValueError(f"config: unknown MHTConfig field(s) {', '.join(bad)}")
        bad = sorted(set(self.run_kwargs) & _RESERVED_KWARGS)
        if bad:
            raise ValueError(f"run_kwargs: {', '.join(bad)} are set by the runner")
        import inspect

        from mhtrack.experiments.pipeline import run_scenario

        known = set(inspect.signature(run_scenario).parameters) - _RESERVED_KWARGS
        bad = sorted(set(self.run_kwargs) - known)
        if bad:
            raise ValueError(f"run_kwargs: unknown keyword(s) {', '.join(bad)} "
                             f"(expected some of {', '.join(sorted(known))})")
        try:
            plain = {k: _plain(v) for k, v in
                     (("scenario", sc), ("config", self.config), ("run_kwargs", self.run_kwargs))}
        except TypeError as e:
            raise ValueError(f"MonteCarloSpec: {e}") from None
        set_ = object.__setattr__
        set_(self, "scenario", plain["scenario"])
        set_(self, "trackers", trackers)
        set_(self, "runs", int(self.runs))
        set_(self, "seed", int(self.seed))
        set_(self, "config", plain["config"])
        set_(self, "run_kwargs", plain["run_kwargs"])

    __hash__ = None  # type: ignore[assignment]

    @property
    def scenario_name(self) -> str:
        return str(self.scenario.get("name", "custom"))

    def to_dict(self) -> dict[str, Any]:
        """JSON form (what ``montecarlo.json`` holds, with ``format``)."""
        return {
            "format": JOB_FORMAT,
            "scenario": self.scenario,
            "trackers": list(self.trackers),
            "runs": self.runs,
            "seed": self.seed,
            "config": self.config,
            "run_kwargs": self.run_kwargs,
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> MonteCarloSpec:
        return cls(scenario=d["scenario"], trackers=tuple(d["trackers"]), runs=d["runs"],
                   seed=d["seed"], config=d.get("config", {}),
                   run_kwargs=d.get("run_kwargs", {}))

    def job(self, tracker: str, run: int) -> dict[str, Any]:
        """Plain-data job of ``tracker`` on run ``run`` (the argument of :func:`run_job`)."""
        job = {
            "format": JOB_FORMAT,
            "scenario": self.scenario,
            "tracker": tracker,
            "run": int(run),
            "base_seed": self.seed,
            "seed": run_seed(self.seed, run),
            "config": self.config,
            "run_kwargs": self.run_kwargs,
        }
        job["job_hash"] = job_hash(job)
        return job

    def jobs(self) -> Iterator[dict[str, Any]]:
        """All jobs, run-major (run 0 of every tracker, then run 1, …)."""
        for i in range(self.runs):
            for t in self.trackers:
                yield self.job(t, i)


def job_hash(job: Mapping[str, Any]) -> str:
    """SHA-256 of a job's parameters (every key but ``job_hash``)."""
    body = {k: v for k, v in job.items() if k != "job_hash"}
    return hashlib.sha256(_canonical(body).encode()).hexdigest()


# ---------------------------------------------------------------------------- one job
def run_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """Run one job (see :meth:`MonteCarloSpec.job`) and return its record: every scalar of
    ``summary()`` plus bookkeeping, and the per-scan lists. Plain data only."""
    from mhtrack.experiments.pipeline import config_with, default_config, run_scenario
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
            record[k] = json.dumps(_plain(v), sort_keys=True)
    for k in PER_SCAN_KEYS:
        if k in summary:
            record[k] = [int(x) if k in _INT_LISTS else float(x) for x in summary[k]]
    return record


def _safe_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """:func:`run_job` that returns ``{"error": traceback}`` instead of raising."""
    try:
        return run_job(job)
    except Exception:
        return {"error": traceback.format_exc()}


# ---------------------------------------------------------------------------- files
def run_path(out_dir: Path, tracker: str, run: int, suffix: str = ".parquet") -> Path:
    return Path(out_dir) / "runs" / tracker / f"run-{run}{suffix}"


def atomic_write(path: Path, data: bytes | str) -> None:
    """Write ``data`` (text is UTF-8) to ``path`` atomically: a temporary file in the same
    folder, then ``os.replace``, so a reader or an interruption never sees half a file."""
    if isinstance(data, str):
        data = data.encode("utf-8")
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _arrow_type(v: Any) -> pa.DataType:
    if isinstance(v, bool):
        return pa.bool_()
    if isinstance(v, int):
        return pa.int64()
    if isinstance(v, str):
        return pa.string()
    return pa.float64()  # floats, and None (a metric that was NaN)


def write_record(path: Path, record: Mapping[str, Any]) -> None:
    """Write one run's record as a one-row Parquet file, atomically."""
    fields, arrays = [], []
    for k, v in record.items():
        if isinstance(v, list):
            t = pa.list_(pa.int64() if k in _INT_LISTS else pa.float64())
        else:
            t = _arrow_type(v)
        fields.append(pa.field(k, t))
        arrays.append(pa.array([v], type=t))
    meta = {b"mhtrack.job_hash": str(record["job_hash"]).encode()}
    table = pa.Table.from_arrays(arrays, schema=pa.schema(fields, metadata=meta))
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        pq.write_table(table, tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def read_record(path: Path) -> dict[str, Any]:
    """The record of a run file (scalars as Python values, per-scan arrays as lists)."""
    row = pq.read_table(path).to_pylist()[0]
    return {k: (math.nan if v is None and k not in PER_SCAN_KEYS else v) for k, v in row.items()}


def stored_hash(path: Path) -> str | None:
    """The ``job_hash`` stored in a run file, or ``None`` if it cannot be read."""
    try:
        meta = pq.read_schema(path).metadata or {}
    except (OSError, pa.ArrowException):
        return None
    h = meta.get(b"mhtrack.job_hash")
    return h.decode() if h is not None else None


def _check_study(spec: MonteCarloSpec, out_dir: Path) -> None:
    path = out_dir / SPEC_FILE
    if not path.is_file():
        return
    try:
        old = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        raise SpecMismatchError(f"{path}: cannot read the stored study ({e})") from None
    new = spec.to_dict()
    differ = [k for k in ("format", *STUDY_FIELDS) if _canonical(old.get(k)) != _canonical(new[k])]
    if differ:
        raise SpecMismatchError(
            f"{out_dir} holds a Monte-Carlo study with other parameters "
            f"(differing from {path}: {', '.join(differ)}); use another --out directory or "
            "delete that one"
        )


# ---------------------------------------------------------------------------- results
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

    @property
    def ok(self) -> bool:
        return not any(self.failures.values()) and not self.missing

    def metric_keys(self) -> list[str]:
        """Numeric scalar columns, in first-seen order."""
        keys: dict[str, None] = {}
        for recs in self.records.values():
            for r in recs:
                for k, v in r.items():
                    if (k not in _NOT_METRICS and not isinstance(v, bool | str | list)
                            and isinstance(v, int | float)):
                        keys.setdefault(k)
        return list(keys)

    def summary(self) -> dict[str, dict[str, Any]]:
        """``{tracker: {metric: mean, …, "std": {metric: std}, "n_runs", "failed",
        "per_scan": {scans, ospa, ospa_std, cardinality, cardinality_std,
        cardinality_true, gospa, gospa_std}}}`` — means under the ``evaluate`` keys plus
        ``t_avg``; NaN where no run has a value."""
        keys = self.metric_keys()
        out: dict[str, dict[str, Any]] = {}
        for t in self.spec.trackers:
            recs = self.records.get(t, [])
            entry: dict[str, Any] = {}
            std: dict[str, float] = {}
            for k in keys:
                vals = np.array([_num(r.get(k)) for r in recs], float)
                entry[k], std[k] = _mean_std(vals)
            entry["std"] = std
            entry["n_runs"] = len(recs)
            entry["failed"] = sorted(self.failures.get(t, {}))
            entry["per_scan"] = _per_scan(recs)
            out[t] = entry
        return out

    def to_markdown(self) -> str:
        """``summary.md``: mean ± std per metric (rows) and tracker (columns)."""
        s = self.summary()
        spec = self.spec
        lines = [
            f"# Monte-Carlo: {spec.scenario_name}",
            "",
            f"{spec.runs} runs per tracker, base seed {spec.seed}; mean ± std over the "
            "successful runs (population std, NaN ignored).",
            "",
            "| metric | " + " | ".join(spec.trackers) + " |",
            "|---|" + "---|" * len(spec.trackers),
        ]
        for k in self.metric_keys():
            cells = [f"{_fmt(s[t][k])} ± {_fmt(s[t]['std'][k])}" for t in spec.trackers]
            lines.append(f"| {k} | " + " | ".join(cells) + " |")
        lines.append("| runs ok | " + " | ".join(str(s[t]["n_runs"]) for t in spec.trackers)
                     + " |")
        failed = [(t, i) for t in spec.trackers for i in s[t]["failed"]]
        if failed or self.missing:
            lines += ["", "## Failed runs", ""]
            lines += [f"* {t} run {i}: see `runs/{t}/run-{i}.error.txt`" for t, i in failed]
            lines += [f"* {t} run {i}: not run" for t, i in self.missing]
        return "\n".join(lines) + "\n"

    def write_reports(self) -> None:
        """Write ``summary.md`` and ``ospa_cardinality.png`` into :attr:`out_dir`."""
        from mhtrack.plotting.metrics import plot_ospa_cardinality
        from mhtrack.plotting.scene import save_figure

        atomic_write(self.out_dir / SUMMARY_FILE, self.to_markdown().encode())
        curves = {t: v["per_scan"] for t, v in self.summary().items() if v["per_scan"]["scans"]}
        if curves:
            cutoff = self.spec.run_kwargs.get("cutoff", 500.0)
            title = f"{self.spec.scenario_name}: mean ± std over {self.spec.runs} runs"
            save_figure(plot_ospa_cardinality(curves, cutoff=cutoff, title=title),
                        self.out_dir / FIGURE_FILE)


def _num(v: Any) -> float:
    return math.nan if v is None else float(v)


def _mean_std(vals: np.ndarray) -> tuple[float, float]:
    vals = vals[np.isfinite(vals)]
    if vals.size == 0:
        return math.nan, math.nan
    return float(vals.mean()), float(vals.std())


def _fmt(v: float) -> str:
    if not math.isfinite(v):
        return "–"
    return f"{v:.4g}"


def _per_scan(recs: Sequence[Mapping[str, Any]]) -> dict[str, list[float]]:
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
            mean[j], std[j] = _mean_std(a[:, j])
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
    spec = MonteCarloSpec.from_dict(json.loads(path.read_text()))
    records: dict[str, list[dict[str, Any]]] = {t: [] for t in spec.trackers}
    failures: dict[str, dict[int, str]] = {t: {} for t in spec.trackers}
    missing: list[tuple[str, int]] = []
    for job in spec.jobs():
        t, i = job["tracker"], job["run"]
        p = run_path(out_dir, t, i)
        if p.is_file() and stored_hash(p) == job["job_hash"]:
            records[t].append(read_record(p))
        elif run_path(out_dir, t, i, ".error.txt").is_file():
            failures[t][i] = run_path(out_dir, t, i, ".error.txt").read_text()
        else:
            missing.append((t, i))
    for t in spec.trackers:
        records[t].sort(key=lambda r: r["run"])
    return MonteCarloResult(spec, out_dir, records, failures, missing)


# ---------------------------------------------------------------------------- runner
def run_montecarlo(
    spec: MonteCarloSpec,
    out_dir: str | os.PathLike[str],
    *,
    executor: str = "local",
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    job_function: Callable[[Mapping[str, Any]], dict[str, Any]] | None = None,
) -> MonteCarloResult:
    """Run (or resume) the study ``spec`` into ``out_dir`` and return its results.

    Parameters
    ----------
    executor : ``"local"`` — a :class:`~concurrent.futures.ProcessPoolExecutor` of
        ``workers`` processes (default ``os.cpu_count()``; ``1`` runs in this process, no
        pool) — or ``"dask"`` — a :class:`distributed.Client` on ``scheduler`` (an address
        such as ``"tcp://host:8786"``, or a ``Client`` / ``LocalCluster`` object).
    progress : a tqdm bar over jobs on stderr.
    job_function : top-level function run on each job instead of :func:`run_job` (tests).

    Jobs already done (run file present with the same ``job_hash``) are skipped. A job that
    raises is recorded in ``runs/<tracker>/run-<i>.error.txt`` and the others go on; see
    :attr:`MonteCarloResult.failures`. Raises :class:`SpecMismatchError` if ``out_dir``
    holds a study with other parameters. Does not write ``summary.md`` or the figure
    (:meth:`MonteCarloResult.write_reports`).
    """
    check_executor(executor, workers, scheduler)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    _check_study(spec, out_dir)
    pending = []
    for job in spec.jobs():
        p = run_path(out_dir, job["tracker"], job["run"])
        if p.is_file():
            h = stored_hash(p)
            if h == job["job_hash"]:
                continue
            if h is not None:
                raise SpecMismatchError(
                    f"{p} holds a run of other parameters (job hash {h[:12]}…, expected "
                    f"{job['job_hash'][:12]}…); use another --out directory or delete it")
        pending.append(job)
    atomic_write(out_dir / SPEC_FILE,
                        (json.dumps(spec.to_dict(), indent=1) + "\n").encode())
    n_total = spec.runs * len(spec.trackers)
    fn = job_function or run_job

    bar = tqdm(total=n_total, initial=n_total - len(pending), unit="run", desc="montecarlo",
               disable=not progress, file=sys.stderr, dynamic_ncols=True)

    n_failed = 0

    def finish(job: Mapping[str, Any], record: Mapping[str, Any] | None, error: str | None
               ) -> None:
        nonlocal n_failed
        t, i = job["tracker"], job["run"]
        err_path = run_path(out_dir, t, i, ".error.txt")
        if error is None and record is not None and "error" in record:
            error = str(record["error"])
        if error is not None:
            atomic_write(err_path, error.encode())
            n_failed += 1
            bar.set_postfix_str(f"{n_failed} failed")
        else:
            assert record is not None
            write_record(run_path(out_dir, t, i), record)
            with contextlib.suppress(FileNotFoundError):
                err_path.unlink()
        bar.update(1)

    try:
        execute(pending, fn, finish, executor=executor, workers=workers, scheduler=scheduler)
    finally:
        bar.close()
    result = load_results(out_dir)
    result.computed = len(pending)
    result.skipped = n_total - len(pending)
    return result


def check_executor(executor: str, workers: int | None, scheduler: Any) -> None:
    """Validate the executor arguments of :func:`execute` (``ValueError`` naming the bad one)."""
    if executor not in ("local", "dask"):
        raise ValueError(f"executor: expected 'local' or 'dask', got {executor!r}")
    if executor == "dask" and scheduler is None:
        raise ValueError("executor 'dask' needs a scheduler address")
    if workers is not None and (isinstance(workers, bool) or workers < 1):
        raise ValueError(f"workers: expected an integer >= 1, got {workers!r}")


def execute(pending: Sequence[Mapping[str, Any]], fn: Callable[..., Any],
            finish: Callable[..., Any], *, executor: str = "local", workers: int | None = None,
            scheduler: Any = None) -> None:
    """Run ``fn(job)`` for every job of ``pending`` and call ``finish(job, record, error)``
    in this process as each one ends: on a Dask cluster (``executor="dask"``, ``scheduler``
    an address or a ``distributed.Client``), in this process (one worker, or one job), or
    in a pool of ``workers`` local processes (default: the CPU count)."""
    check_executor(executor, workers, scheduler)
    if not pending:
        return
    n_workers = workers or os.cpu_count() or 1
    if executor == "dask":
        _run_dask(pending, fn, scheduler, finish)
    elif n_workers == 1 or len(pending) <= 1:
        for job in pending:
            _run_inline(job, fn, finish)
    else:
        _run_pool(pending, fn, n_workers, finish)


def _run_inline(job: Mapping[str, Any], fn: Callable[..., Any], finish: Callable[..., Any]
                ) -> None:
    try:
        record = fn(job)
    except Exception:
        finish(job, None, traceback.format_exc())
        return
    finish(job, record, None)


def _exc_text(exc: BaseException) -> str:
    text = "".join(traceback.format_exception(exc))
    cause = exc.__cause__  # ProcessPoolExecutor attaches the worker's traceback here
    return text if cause is None else text + "\n" + str(cause)


def _run_pool(pending: Sequence[Mapping[str, Any]], fn: Callable[..., Any], workers: int,
              finish: Callable[..., Any]) -> None:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # "fork" where there is one: "spawn" would re-import the caller's __main__ module, which
    # breaks scripts without an ``if __name__ == "__main__"`` guard.
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    with ProcessPoolExecutor(max_workers=min(workers, len(pending)), mp_context=ctx) as pool:
        futures = {pool.submit(fn, job): job for job in pending}
        try:
            for fut in as_completed(futures):
                exc = fut.exception()
                if exc is not None:
                    finish(futures[fut], None, _exc_text(exc))
                else:
                    finish(futures[fut], fut.result(), None)
        except BaseException:  # e.g. Ctrl-C: drop queued jobs; finished ones are on disk
            pool.shutdown(wait=False, cancel_futures=True)
            raise


def _run_dask(pending: Sequence[Mapping[str, Any]], fn: Callable[..., Any], scheduler: Any,
              finish: Callable[..., Any]) -> None:
    from distributed import Client, as_completed

    own = not isinstance(scheduler, Client)
    if own:
        address = getattr(scheduler, "scheduler_address", scheduler)  # a LocalCluster
        client = Client(address)
    else:
        client = scheduler
    try:
        if not pending:
            return
        futures = {
            client.submit(fn, job, pure=False,
                          key=f"mhtrack-mc-{job['tracker']}-{job['run']}-{job['job_hash'][:12]}"):
            job for job in pending
        }
        try:
            for fut in as_completed(list(futures)):
                job = futures[fut]
                if fut.status == "error":
                    exc = fut.exception()
                    tb = fut.traceback()
                    text = "".join(traceback.format_exception(type(exc), exc, tb))
                    finish(job, None, text)
                elif fut.status == "cancelled":
                    finish(job, None, "cancelled by the Dask cluster\n")
                else:
                    finish(job, fut.result(), None)
                fut.release()
        except BaseException:
            client.cancel(list(futures))
            raise
    finally:
        if own:
            client.close()
