"""The clutter-shift study (``mhtrack reproduce clutter-shift``): on ``crossing-changing``,
whose clutter components appear, vanish, split, merge and drift, the MHT with four ways
of knowing the clutter intensity, over paired runs:

* ``known`` — the true ``κ_k(z) = S λ_k c_k(z)`` of the scenario at every scan
  (:class:`TrueClutter`, an oracle: the best any estimator can do);
* ``uniform`` — ``κ̂ = M̂_k / A``, the mean plot count of the last ``W = 5`` scans spread
  evenly over the region (:class:`UniformCountClutter`);
* ``gmm`` — P1's MHT-GMM estimator (fixed deletion threshold; :mod:`mhtrack.clutter.gmm`);
* ``agmm`` — P1's MHT-AGMM estimator (adaptive number of components, eq. 12;
  :mod:`mhtrack.clutter.agmm`);
* any other name of :data:`mhtrack.build.CLUTTER_ESTIMATOR_CLASSES` on request (``fgmm``,
  ``map``, ...; :func:`study_methods`), built by
  :func:`~mhtrack.build.make_clutter_estimator` with its defaults and compared with ``gmm``
  and ``uniform``.

Run ``i`` simulates with ``run_seed(seed, i, "spawn")``, the same plots for every method,
so the methods pair run by run. Each job (one method, one run) tracks with the tracker's
default configuration and ``output`` and scores the tracks (:func:`mhtrack.metrics.
evaluate`) and, after every scan, the intensity the tracker's own estimator holds
against the truth: ``IAE_k = ∫|κ̂_k − κ_k|`` on a ``resolution²`` grid
(:mod:`mhtrack.metrics.clutter`). Jobs are stored in ``DIR/jobs/<method>/run-<i>.json``
by the job runner (:mod:`mhtrack.experiments.jobs`); a rerun resumes.
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.experiments.jobs import SPACED, Job, JobStore, JsonRecords, run_jobs, run_seed
from mhtrack.metrics.paired import PairedComparison, compare_paired, paired_by_run
from mhtrack.records import Scan

#: Methods of the study, in report order, with what each is.
METHODS: dict[str, str] = {
    "known": "true κ_k(z) of the scenario at every scan (oracle)",
    "uniform": "κ̂ = mean plot count of the last 5 scans / region area",
    "gmm": "P1's MHT-GMM estimator: EM from K = 8, fixed deletion threshold 0.05",
    "agmm": "P1's MHT-AGMM estimator: EM from K = 8, adaptive number of components (eq. 12)",
}
PRESET = "crossing-changing"
DEFAULT_RUNS = 50
#: IAE grid: 200² cells of 40 m on the 8 km region (the narrowest component has σ = 120 m).
RESOLUTION = 200
UNIFORM_WINDOW = 5
#: Comparisons (A, B): P1's claim first, then each estimator against the simpler one and
#: the oracle's headroom.
PAIRS: tuple[tuple[str, str], ...] = (
    ("agmm", "gmm"), ("agmm", "uniform"), ("gmm", "uniform"), ("known", "agmm"))
#: Metrics compared: key → (label, higher is better, decimals).
METRICS: dict[str, tuple[str, bool, int]] = {
    "iae_mean": ("clutter error ∫|κ̂ − κ| (plots/scan)", False, 2),
    "ospa_mean": ("OSPA mean (m)", False, 1),
    "ospa2_mean": ("OSPA(2) mean (m)", False, 1),
    "hota": ("HOTA", True, 4),
    "rcc": ("Rcc", True, 4),
    "coverage": ("coverage", True, 4),
    "mota": ("MOTA", True, 4),
    "n_track_ids": ("track ids", False, 2),
    "l_avg": ("Lavg (s)", True, 2),
}
JOBS_DIR = "jobs"
STORE = JsonRecords()


class TrueClutter(ClutterEstimator):
    """The scenario's true intensity ``κ_k(z) = S λ_k c_k(z)`` at the last scan's index."""

    name = "true"

    def __init__(self, model: Any, n_sensors: int = 1) -> None:
        self.model, self.n_sensors, self.scan = model, int(n_sensors), 0

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        self.scan = int(scan.index)

    def intensity(self, z: np.ndarray) -> np.ndarray:
        return self.n_sensors * np.asarray(self.model.intensity(z, self.scan), float)

    def get_state(self) -> dict[str, Any]:
        return {"scan": self.scan}

    def set_state(self, state: dict[str, Any]) -> None:
        self.scan = int(state["scan"])


class UniformCountClutter(ClutterEstimator):
    """``κ̂ = M̂ / A``: the mean number of plots of the last ``window`` scans (the Poisson
    ML count, targets' plots included) spread evenly over an area ``A``."""

    name = "uniform-count"

    def __init__(self, area: float, window: int = UNIFORM_WINDOW) -> None:
        self.area, self.window = float(area), int(window)
        self.counts: list[int] = []

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        self.counts = [*self.counts, len(scan)][-self.window:]

    @property
    def count_(self) -> float:
        return float(np.mean(self.counts)) if self.counts else 0.0

    def intensity(self, z: np.ndarray) -> np.ndarray:
        return np.full(len(z), self.count_ / self.area)

    def get_state(self) -> dict[str, Any]:
        return {"counts": list(self.counts)}

    def set_state(self, state: dict[str, Any]) -> None:
        self.counts = [int(c) for c in state["counts"]]


def study_methods() -> tuple[str, ...]:
    """Every method the study can run: :data:`METHODS` (its default set) and every other
    registered estimator but the constant ``known`` (here ``known`` is the oracle)."""
    from mhtrack.build import CLUTTER_ESTIMATOR_CLASSES

    return (*METHODS, *(n for n in CLUTTER_ESTIMATOR_CLASSES if n not in METHODS))


def describe(method: str) -> str:
    """One line on ``method`` (:data:`METHODS`, else the estimator class's docstring)."""
    if method in METHODS:
        return METHODS[method]
    from mhtrack.build import CLUTTER_ESTIMATOR_CLASSES

    doc = (CLUTTER_ESTIMATOR_CLASSES[method].__doc__ or method).strip().split("\n\n")[0]
    return " ".join(doc.split())


def study_pairs(methods: Sequence[str]) -> tuple[tuple[str, str], ...]:
    """:data:`PAIRS`, then every further estimator against ``gmm`` and ``uniform``."""
    extra = [m for m in methods if m not in METHODS]
    return (*PAIRS, *((m, b) for m in extra for b in ("gmm", "uniform")))


def make_estimator(method: str, scenario: Any,
                   clutter_params: Mapping[str, Any] | None = None) -> ClutterEstimator:
    """A fresh estimator of ``method`` (:func:`study_methods`) for ``scenario``."""
    from mhtrack.build import make_clutter_estimator

    if method == "known":
        return TrueClutter(scenario.clutter, len(scenario.sensors))
    if method == "uniform":
        return UniformCountClutter(scenario.region.area)
    if method in study_methods():
        return make_clutter_estimator(method, **dict(clutter_params or {}))
    raise ValueError(f"unknown method {method!r} (expected {', '.join(study_methods())})")


def _probe(scans: Iterable[Scan], tracker: Any, sim: Any, grid: np.ndarray, cell: float,
           iae: list[float], n_comp: list[int]) -> Iterator[Scan]:
    """Yield the scans to the tracker; once it has stepped one, append the IAE of its
    estimator's intensity at that scan and its number of Gaussian components (−1 for an
    estimator without a mixture)."""
    from mhtrack.metrics.clutter import integrated_absolute_error, true_intensity_grid

    for scan in scans:
        yield scan
        true = true_intensity_grid(sim, int(scan.index), grid)
        est = np.asarray(tracker.clutter.intensity(grid), float)
        iae.append(integrated_absolute_error(est, true, cell))
        mix = getattr(tracker.clutter, "mixture_", None)
        n_comp.append(-1 if mix is None else len(mix.weights))


def run_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """One method on one run (module docstring): the tracking metrics, ``t_avg`` and the
    clutter error ``iae`` per scan and its mean ``iae_mean``."""
    from mhtrack.build import config_with, default_config
    from mhtrack.experiments.pipeline import track
    from mhtrack.metrics import evaluate
    from mhtrack.mht import MHTTracker
    from mhtrack.scenario import Scenario, simulate

    scenario = Scenario.from_dict(job["scenario"])
    sim = simulate(scenario, seed=job["seed"])
    config = config_with(default_config(scenario), **job["config"])
    tracker = MHTTracker(config, make_estimator(job["method"], scenario,
                                                job.get("clutter_params")))
    grid, cell = scenario.region.grid(int(job["resolution"]))
    iae: list[float] = []
    n_comp: list[int] = []
    tracker_log = logging.getLogger("mhtrack.mht.tracker")  # caps are kept in the record
    level = tracker_log.level
    tracker_log.setLevel(logging.ERROR)
    try:
        run = track(tracker, _probe(sim.plots.scans(), tracker, sim, grid, cell, iae, n_comp),
                    name=job["method"], output=job["output"])
    finally:
        tracker_log.setLevel(level)
    ev = evaluate(run.tracks, sim.truth, plots=sim.plots, cutoff=job["cutoff"],
                  order=job["order"]).to_dict()
    rec: dict[str, Any] = {"method": job["method"], "run": job["run"], "seed": job["seed"],
                           "t_avg": run.t_avg, "iae_mean": float(np.mean(iae)), "iae": iae,
                           "n_components": n_comp, "caps": run.caps}
    for k in METRICS:
        if k in ev:
            rec[k] = ev[k]
    rec["n_false"] = ev.get("n_false")
    return rec


@dataclass
class ClutterShiftStudy:
    """What :func:`clutter_shift` computed: the records per method (sorted by run), the
    failures, the paired comparisons and the parameters."""

    out_dir: Path
    params: dict[str, Any]
    records: dict[str, list[dict[str, Any]]]
    errors: dict[str, str]
    paired: list[PairedComparison] = field(default_factory=list)
    computed: int = 0
    skipped: int = 0


def make_jobs(runs: int, seed: int, scenario: Mapping[str, Any], methods: Sequence[str],
              base: Mapping[str, Any]) -> list[Job]:
    """One job per (method, run); run ``i`` seeds ``run_seed(seed, i, "spawn")``."""
    jobs = []
    for i in range(runs):
        s = run_seed(seed, i, "spawn")
        for m in methods:
            jobs.append(Job.of(f"{m}/run-{i}", {**base, "scenario": scenario, "method": m,
                                                "run": i, "seed": s}, SPACED))
    return jobs


def paired_comparisons(records: Mapping[str, Sequence[Mapping[str, Any]]],
                       pairs: Sequence[tuple[str, str]] = PAIRS) -> list[PairedComparison]:
    """Every pair of :data:`PAIRS` on every metric of :data:`METRICS`, paired by run."""
    out = []
    for a, b in pairs:
        if not records.get(a) or not records.get(b):
            continue
        for k, (label, hb, digits) in METRICS.items():
            va, vb, _ = paired_by_run(records[a], records[b], k)
            out.append(compare_paired(va, vb, metric=k, name_a=a, name_b=b, higher_better=hb,
                                      digits=digits, label=label))
    return out


def default_scenario() -> Any:
    """The study's scenario: the :data:`PRESET` preset."""
    from mhtrack.scenario import preset

    return preset(PRESET)


def clutter_shift(out_dir: str | os.PathLike[str], runs: int = DEFAULT_RUNS, seed: int = 0, *,
                  scenario: Any = None, methods: Sequence[str] = tuple(METHODS),
                  config: Mapping[str, Any] | None = None, output: str = "history",
                  resolution: int = RESOLUTION, executor: str = "local",
                  workers: int | None = None, scheduler: Any = None,
                  progress: bool = False) -> ClutterShiftStudy:
    """Run (or resume) the study into ``out_dir/jobs/`` (module docstring). ``scenario``
    replaces the ``crossing-changing`` preset (tests use a shortened one)."""
    bad = [m for m in methods if m not in study_methods()]
    if bad:
        raise ValueError(f"unknown method(s) {', '.join(bad)} "
                         f"(expected {', '.join(study_methods())})")
    sc = default_scenario() if scenario is None else scenario
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    base = {"config": dict(config or {}), "output": output, "cutoff": 500.0, "order": 2.0,
            "resolution": int(resolution)}
    jobs = make_jobs(runs, seed, sc.to_dict(), methods, base)
    store = JobStore(out_dir / JOBS_DIR, STORE)
    done = run_jobs(jobs, run_job, store, executor=executor, workers=workers,
                    scheduler=scheduler, progress=progress, desc="clutter-shift", unit="run")
    records: dict[str, list[dict[str, Any]]] = {m: [] for m in methods}
    errors: dict[str, str] = {}
    for j in jobs:
        if store.is_done(j):
            records[j.params["method"]].append(store.load(j))
        else:
            errors[j.key] = store.error(j) or "not run"
    for recs in records.values():
        recs.sort(key=lambda r: r["run"])
    params = {"scenario": sc.name, "runs": runs, "seed": seed, "methods": list(methods),
              **base, "method_descriptions": {m: describe(m) for m in methods}}
    return ClutterShiftStudy(out_dir, params, records, errors,
                             paired_comparisons(records, study_pairs(methods)),
                             done.computed, done.skipped)


def mean_iae_per_scan(records: Sequence[Mapping[str, Any]]) -> list[float]:
    """The clutter error per scan, mean over runs (NaN where no run has the scan)."""
    if not records:
        return []
    n = max(len(r["iae"]) for r in records)
    a = np.full((len(records), n), math.nan)
    for i, r in enumerate(records):
        a[i, :len(r["iae"])] = r["iae"]
    return [float(v) for v in np.nanmean(a, axis=0)]
