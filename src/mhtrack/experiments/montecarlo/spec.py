"""The parameters of a Monte-Carlo study (:class:`MonteCarloSpec`), its jobs, and the check
that an output directory holds the same study."""

from __future__ import annotations

import dataclasses
import inspect
import json
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.experiments.jobs import COMPACT, Job, JobPlan, run_seed
from mhtrack.io.jsonsafe import to_jsonable

#: Bumped when the meaning of a job (and so its hash) changes.
JOB_FORMAT = 2  # 2: run_scenario's history output (mhtrack.mht.history)
SPEC_FILE = "montecarlo.json"
RUNS_DIR = "runs"
#: Trackers of a study unless given: P1's three, in P1 Table 3's order.
DEFAULT_TRACKERS: tuple[str, ...] = ("mht", "mht-gmm", "mht-agmm")
#: Spec fields that must match for a directory to be resumed.
STUDY_FIELDS = ("scenario", "seed", "config", "run_kwargs")
#: Most runs per tracker of one study: its plan is lazy (:meth:`MonteCarloSpec.plan`), but
#: the summary reads every record back, one file each.
MAX_RUNS = 1_000_000
#: ``run_scenario`` arguments the runner sets itself.
RESERVED_KWARGS = frozenset({"scenario", "seed", "tracker", "config", "progress"})


class SpecMismatchError(ValueError):
    """The output directory holds runs of a study with other parameters."""


def _plain(obj: Any) -> Any:
    """JSON data of ``obj`` (tuples as lists, NumPy scalars as numbers, NaN kept);
    ``TypeError`` for anything else."""
    return to_jsonable(obj, strict=True, nonfinite_as_null=False)


def _canonical(obj: Any) -> str:
    return json.dumps(obj, sort_keys=True, separators=COMPACT)


def job_key(tracker: str, run: int) -> str:
    """The key (and store path, under ``runs/``) of ``tracker`` on run ``run``."""
    return f"{tracker}/run-{int(run)}"


@dataclass(frozen=True)
class MonteCarloSpec:
    """A Monte-Carlo study.

    Parameters
    ----------
    scenario : Scenario or its dict form (:meth:`Scenario.to_dict`); stored as the dict.
    trackers : tracker names (:data:`mhtrack.names.TRACKERS`).
    runs : number of runs per tracker, 1 to :data:`MAX_RUNS`.
    seed : base seed; run ``i`` simulates with ``run_seed(seed, i)`` (stream ``"spawn"``
        of :mod:`mhtrack.experiments.jobs.seeds`), the same for every tracker.
    config : :class:`~mhtrack.mht.MHTConfig` fields to change from their defaults.
    run_kwargs : further keywords of :func:`~mhtrack.experiments.pipeline.run_scenario`
        (``clutter_density``, ``cutoff``, ``order``, …), forwarded verbatim; JSON data.
    """

    scenario: Mapping[str, Any]
    trackers: tuple[str, ...] = DEFAULT_TRACKERS
    runs: int = 10
    seed: int = 0
    config: Mapping[str, Any] = field(default_factory=dict)
    run_kwargs: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        from mhtrack.experiments.pipeline import run_scenario
        from mhtrack.mht import MHTConfig
        from mhtrack.names import TRACKERS
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
        if self.runs > MAX_RUNS:
            raise ValueError(f"runs: expected at most {MAX_RUNS:,} runs per tracker, got "
                             f"{self.runs:,}")
        fields = {f.name for f in dataclasses.fields(MHTConfig)}
        bad = sorted(set(self.config) - fields)
        if bad:
            raise ValueError(f"config: unknown MHTConfig field(s) {', '.join(bad)}")
        bad = sorted(set(self.run_kwargs) & RESERVED_KWARGS)
        if bad:
            raise ValueError(f"run_kwargs: {', '.join(bad)} are set by the runner")
        known = set(inspect.signature(run_scenario).parameters) - RESERVED_KWARGS
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

    @classmethod
    def from_file(cls, path: str | Path) -> MonteCarloSpec:
        """The study stored in ``path`` (``montecarlo.json``), every problem one
        :class:`~mhtrack.errors.InputError` line naming the file and the key."""
        return read_spec_file(Path(path))

    def job(self, tracker: str, run: int) -> Job:
        """The job of ``tracker`` on run ``run`` (its dict is the argument of
        :func:`~mhtrack.experiments.montecarlo.job.run_job`)."""
        params = {
            "format": JOB_FORMAT,
            "scenario": self.scenario,
            "tracker": tracker,
            "run": int(run),
            "base_seed": self.seed,
            "seed": run_seed(self.seed, run, "spawn"),
            "config": self.config,
            "run_kwargs": self.run_kwargs,
        }
        return Job.of(job_key(tracker, run), params, COMPACT)

    def jobs(self) -> Iterator[Job]:
        """All jobs, run-major (run 0 of every tracker, then run 1, …)."""
        return iter(self.plan())

    def plan(self) -> JobPlan:
        """All jobs as a lazy :class:`~mhtrack.experiments.jobs.JobPlan`, run-major: job
        ``k`` is run ``k // T`` of tracker ``k % T`` (``T`` trackers), made when asked
        for, so a study of :data:`MAX_RUNS` runs costs no memory before its first job."""
        n = len(self.trackers)
        return JobPlan(self.runs * n, lambda k: self.job(self.trackers[k % n], k // n))


def check_study(spec: MonteCarloSpec, out_dir: Path) -> None:
    """Raise :class:`SpecMismatchError` if ``out_dir`` holds a study whose scenario, seed,
    config, run keywords or job format differ from ``spec``'s."""
    path = Path(out_dir) / SPEC_FILE
    if not path.is_file():
        return
    old = read_spec_file(path).to_dict()
    new = spec.to_dict()
    differ = [k for k in ("format", *STUDY_FIELDS) if _canonical(old.get(k)) != _canonical(new[k])]
    if differ:
        raise SpecMismatchError(
            f"{out_dir} holds a Monte-Carlo study with other parameters "
            f"(differing from {path}: {', '.join(differ)}); use another --out directory or "
            "delete that one"
        )


def read_spec_file(path: Path) -> MonteCarloSpec:
    """:meth:`MonteCarloSpec.from_file`."""
    from mhtrack.io.jsonfile import key_error, read_json_object

    d = read_json_object(path, "a Monte-Carlo study", ("scenario", "trackers", "runs", "seed"))
    if not isinstance(d["trackers"], list):
        raise key_error(path, "trackers", "expected an array of tracker names")
    for key in ("config", "run_kwargs"):
        if not isinstance(d.get(key, {}), dict):
            raise key_error(path, key, "expected an object")
    try:
        return MonteCarloSpec.from_dict(d)
    except SpecMismatchError:
        raise
    except (ValueError, TypeError) as e:
        msg = str(e)
        key = msg.split(":", 1)[0] if ":" in msg and " " not in msg.split(":", 1)[0] else None
        raise key_error(path, key, msg.split(": ", 1)[1] if key else msg) from None
