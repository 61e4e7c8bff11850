"""The clutter-scenes study (``mhtrack reproduce clutter-scenes``): every clutter estimator
of :mod:`mhtrack.experiments.scene_methods` tracking rotating radars in the changing clutter
scenes of :mod:`mhtrack.scenario.scenes` (weather cells drifting and growing, ground
clutter, a sea band whose sea state rises, a burst), over paired runs.

Run ``i`` of a scene simulates with ``run_seed(seed, i, "spawn")``, the same plots for
every method, so the methods pair run by run. Each job (one scene, one method, one run)
builds the tracker ``mhtrack run`` would build for the scene (:class:`~mhtrack.pipeline.
Pipeline`, every default chosen by the pipeline): for a registered estimator or variant the
tracker ``mht-<estimator>`` with its ``clutter_params``
(:func:`~mhtrack.experiments.scene_methods.method_tracker`), for ``known``, ``uniform`` (and
an estimator no tracker name uses) tracker :data:`TRACKER` given the method's per-radar
estimator; it tracks frame by frame
and scores:

* the **clutter error** after every frame, of the frame's radar ``s``:
  ``IAE = ∫_{C_s} |κ̂_s(x) − κ_s(x, t)| dx`` over the radar's coverage ``C_s`` (geodesic
  range ``<= max_range``) within the region, on the region's ``resolution²`` grid
  (midpoint rule; plots per rotation), ``κ_s`` the true intensity of that rotation
  (:class:`~mhtrack.scenario.scene_truth.RadarTruth`); ``iae_mean`` is its mean over
  the frames;
* the tracks in both views, collected from the same run (``history``: every confirmed
  track's rows back to its start; ``online``: the rows as reported at each frame),
  each scored by :func:`mhtrack.metrics.evaluate` (OSPA, HOTA, ids, coverage,
  fragmentations, id switches) and counted for **false tracks** (track ids never matched
  to a target by CLEAR-MOT);
* times (not compared): the tracker's mean step ``t_avg``, the estimator's own time per
  frame ``t_clutter`` (its ``update`` and ``intensity`` calls by the tracker), the
  tracker's CPU time over the run ``t_cpu`` (``time.thread_time`` around the tracking, the
  probe's own removed; the shared machine's load does not inflate it) and the job's wall
  time ``t_run`` (simulation, tracking, probes and scoring).

Jobs are stored in ``DIR/jobs/<scene>/<method>/run-<i>.json`` (a rerun resumes); the
result does not depend on the executor or the number of workers.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.experiments.jobs import SPACED, Job, JobStore, JsonRecords, run_jobs, run_seed
from mhtrack.experiments.scene_methods import (
    ORACLE,
    UNIFORM,
    VARIANTS,
    all_methods,
    describe,
    known_methods,
)
from mhtrack.metrics.clutter import integrated_absolute_error
from mhtrack.metrics.paired import PairedComparison, compare_paired, paired_by_run
from mhtrack.records import Scan

PRESET = "radars-clutter"
DEFAULT_RUNS = 50
#: The tracker of ``known`` and ``uniform`` (its estimator is replaced); every other
#: method's tracker is built with its own estimator (module docstring).
TRACKER = "mht-gmm"
#: IAE grid: 100² cells (1.35 × 1.08 km on ``radars-clutter``; its narrowest clutter, the
#: ground clutter, has L = 4 km).
RESOLUTION = 100
#: Metrics compared: key → (label, higher is better, decimals).
METRICS: dict[str, tuple[str, bool, int]] = {
    "iae_mean": ("clutter error ∫|κ̂ − κ| (plots/rotation)", False, 2),
    "ospa_history": ("OSPA, history view (m)", False, 1),
    "ospa_online": ("OSPA, online view (m)", False, 1),
    "false_tracks_history": ("false tracks, history view", False, 2),
    "false_tracks_online": ("false tracks, online view", False, 2),
    "ids_history": ("track ids", False, 2),
    "hota_history": ("HOTA, history view", True, 4),
}
POOLED = "all scenes"
JOBS_DIR = "jobs"
STORE = JsonRecords()


class TimedClutter(ClutterEstimator):
    """``inner`` with the time of the tracker's calls summed in ``seconds``."""

    def __init__(self, inner: ClutterEstimator) -> None:
        self.inner, self.seconds = inner, 0.0

    @property
    def name(self) -> str:  # type: ignore[override]
        return str(self.inner.name)

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        t0 = time.perf_counter()
        self.inner.update(scan, in_track_gates)
        self.seconds += time.perf_counter() - t0

    def intensity(self, z: np.ndarray) -> np.ndarray:
        t0 = time.perf_counter()
        out = self.inner.intensity(z)
        self.seconds += time.perf_counter() - t0
        return out

    def forget(self, used: np.ndarray) -> None:
        self.inner.forget(used)

    def reference_intensity(self) -> float:
        return self.inner.reference_intensity()

    def get_state(self) -> dict[str, Any]:
        return self.inner.get_state()

    def set_state(self, state: dict[str, Any]) -> None:
        self.inner.set_state(state)


def _probe(frames: Any, est: ClutterEstimator, truth: Any, cell: float,
           iae: list[float], cpu: list[float]) -> Iterator[Scan]:
    """Yield the frames to the tracker; once it has stepped one, append the clutter error
    of the frame's radar (module docstring), adding the probe's own CPU time
    (``time.thread_time``) to ``cpu[0]``. The truth is computed once per rotation of each
    radar (the radars' frames interleave)."""
    cache: dict[int, tuple[float, np.ndarray]] = {}  # radar → (rotation, its truth)
    for f in frames:
        yield f
        if not len(f):
            continue
        c0 = time.thread_time()
        sid = int(f.sensor[0])
        rotation = truth.rotation_time(sid, float(f.time))
        if sid not in cache or cache[sid][0] != rotation:
            cache[sid] = (rotation, truth.intensity(sid, float(f.time)))
        cover = truth.coverage(sid)
        kappa_hat = np.asarray(est.intensity(truth.xy), float)
        iae.append(integrated_absolute_error(kappa_hat[cover], cache[sid][1][cover], cell))
        cpu[0] += time.thread_time() - c0


def _view(tracks: Any, sim: Any, cutoff: float, order: float) -> dict[str, float]:
    from mhtrack.metrics import evaluate

    ev = evaluate(tracks, sim.truth, plots=sim.plots, cutoff=cutoff, order=order)
    d = ev.to_dict()
    matched = len(np.unique(ev.clear_mot.matching.track_id))
    return {"ospa": d["ospa_mean"], "hota": d["hota"], "ids": d["n_track_ids"],
            "false_tracks": int(ev.n_tracks - matched), "coverage": d["coverage"],
            "fragmentations": d["fragmentations"], "id_switches": d["id_switches"]}


def run_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """One method on one run of one scene (module docstring)."""
    from mhtrack.experiments.pipeline import scenario_source
    from mhtrack.experiments.scene_methods import has_tracker, make_method, method_tracker
    from mhtrack.pipeline import Pipeline, TrackOptions, feed, step_frames
    from mhtrack.scenario import Scenario, simulate
    from mhtrack.scenario.scene_truth import RadarTruth
    from mhtrack.sinks import TrackCollector

    t_start = time.perf_counter()
    scenario = Scenario.from_dict(job["scenario"])
    sim = simulate(scenario, seed=job["seed"])
    method = job["method"]
    if not has_tracker(method):  # known, uniform, an estimator without a tracker name
        pipe = Pipeline(scenario_source(scenario, sim.plots), TrackOptions(tracker=TRACKER))
        est = make_method(method, scenario, job.get("params"))
    else:
        name, kw = method_tracker(method, job.get("params"))
        pipe = Pipeline(scenario_source(scenario, sim.plots),
                        TrackOptions(tracker=name, clutter_params=kw or None))
        est = pipe.tracker.clutter
    timed = TimedClutter(est)
    pipe.tracker.clutter = timed
    grid, cell = scenario.region.grid(int(job["resolution"]))
    truth = RadarTruth(scenario, grid)
    iae: list[float] = []
    probe_cpu = [0.0]
    views = {v: TrackCollector(v) for v in ("history", "online")}
    tracker_log = logging.getLogger("mhtrack.mht.tracker")  # caps are kept in the record
    level = tracker_log.level
    tracker_log.setLevel(logging.ERROR)
    try:
        frames = _probe(pipe.source, est, truth, cell, iae, probe_cpu)
        c0 = time.thread_time()
        stats, _ = feed(step_frames(pipe.tracker, frames, name=job["method"]),
                        list(views.values()))
        t_cpu = time.thread_time() - c0 - probe_cpu[0]
    finally:
        tracker_log.setLevel(level)
    rec: dict[str, Any] = {"scene": job["scene"], "method": job["method"], "run": job["run"],
                           "seed": job["seed"], "iae_mean": float(np.mean(iae)) if iae
                           else float("nan"), "n_frames": len(stats)}
    for v, rows in views.items():
        for k, x in _view(rows.tracks(), sim, job["cutoff"], job["order"]).items():
            rec[f"{k}_{v}"] = x
    steps = [s.time_s for s in stats]
    rec.update(t_avg=float(np.mean(steps)) if steps else float("nan"),
               t_clutter=timed.seconds / max(len(stats), 1),
               t_run=time.perf_counter() - t_start, t_cpu=t_cpu,
               caps=sorted({k for s in stats for k in s.caps}))
    return rec


@dataclass
class ClutterScenesStudy:
    """What :func:`clutter_scenes` computed: per scene and method the records (sorted by
    run), the failures, the paired comparisons per scene (and pooled) and the parameters."""

    out_dir: Path
    params: dict[str, Any]
    records: dict[str, dict[str, list[dict[str, Any]]]]
    errors: dict[str, str]
    paired: dict[str, list[PairedComparison]] = field(default_factory=dict)
    computed: int = 0
    skipped: int = 0


def study_pairs(methods: Sequence[str]) -> list[tuple[str, str]]:
    """The comparisons ``(A, B)``: every estimator against ``gmm`` (P1's) and against
    ``uniform``, ``gmm`` against ``uniform``, the oracle's headroom over ``gmm`` and each
    variant against its estimator (only pairs whose two methods are run)."""
    est = [m for m in methods if m not in (ORACLE, UNIFORM, "gmm")]
    pairs = [(m, "gmm") for m in est] + [(m, UNIFORM) for m in est]
    pairs += [("gmm", UNIFORM), (UNIFORM, "gmm"), (ORACLE, "gmm")]
    pairs += [(v, VARIANTS[v][0]) for v in methods if v in VARIANTS]  # each ablation
    seen, out = set(), []
    for a, b in pairs:
        if a in methods and b in methods and (b, a) not in seen and (a, b) not in seen:
            seen.add((a, b))
            out.append((a, b))
    return out


def paired_comparisons(records: Mapping[str, Sequence[Mapping[str, Any]]],
                       pairs: Sequence[tuple[str, str]]) -> list[PairedComparison]:
    """Every pair on every metric of :data:`METRICS`, paired by ``run``."""
    out = []
    for a, b in pairs:
        if not records.get(a) or not records.get(b):
            continue
        for k, (label, hb, digits) in METRICS.items():
            va, vb, _ = paired_by_run(records[a], records[b], k)
            out.append(compare_paired(va, vb, metric=k, name_a=a, name_b=b, higher_better=hb,
                                      digits=digits, label=label))
    return out


def pooled(records: Mapping[str, Mapping[str, Sequence[Mapping[str, Any]]]],
           runs: int) -> dict[str, list[dict[str, Any]]]:
    """The records of every scene as one set, run ``i`` of the ``j``-th scene renumbered
    ``j·runs + i`` (pairs stay within a scene and run)."""
    out: dict[str, list[dict[str, Any]]] = {}
    for j, by_method in enumerate(records.values()):
        for m, recs in by_method.items():
            out.setdefault(m, []).extend({**r, "run": j * runs + int(r["run"])} for r in recs)
    return out


def default_base() -> Any:
    """The study's base scenario: the :data:`PRESET` preset."""
    from mhtrack.scenario import preset

    return preset(PRESET)


def clutter_scenes(out_dir: str | os.PathLike[str], runs: int = DEFAULT_RUNS, seed: int = 0,
                   *, base: Any = None, scenes: Sequence[str] | None = None,
                   methods: Sequence[str] | None = None,
                   params: Mapping[str, Mapping[str, Any]] | None = None,
                   resolution: int = RESOLUTION, executor: str = "local",
                   workers: int | None = None, scheduler: Any = None,
                   progress: bool = False) -> ClutterScenesStudy:
    """Run (or resume) the study into ``out_dir/jobs/`` (module docstring). ``base``
    replaces the ``radars-clutter`` preset (tests use a shortened one); ``scenes``: names
    of :data:`~mhtrack.scenario.scenes.SCENES` (default all); ``methods``: default
    :func:`~mhtrack.experiments.scene_methods.all_methods`; ``params``: estimator keywords
    per method."""
    from mhtrack.scenario.scenes import SCENES, with_clutter_scene

    methods = tuple(all_methods() if methods is None else methods)
    scenes = tuple(SCENES if scenes is None else scenes)
    bad = [m for m in methods if m not in known_methods()]
    if bad:
        raise ValueError(f"unknown method(s) {', '.join(bad)} "
                         f"(expected {', '.join(known_methods())})")
    bad = [s for s in scenes if s not in SCENES]
    if bad:
        raise ValueError(f"unknown scene(s) {', '.join(bad)} (expected {', '.join(SCENES)})")
    sc0 = default_base() if base is None else base
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    common = {"cutoff": 500.0, "order": 2.0, "resolution": int(resolution)}
    jobs = []
    for scene in scenes:
        sdict = with_clutter_scene(sc0, scene).to_dict()
        for i in range(runs):
            s = run_seed(seed, i, "spawn")
            for m in methods:
                p = {**common, "scenario": sdict, "scene": scene, "method": m, "run": i,
                     "seed": s, "params": dict((params or {}).get(m, {}))}
                jobs.append(Job.of(f"{scene}/{m}/run-{i}", p, SPACED))
    store = JobStore(out_dir / JOBS_DIR, STORE)
    done = run_jobs(jobs, run_job, store, executor=executor, workers=workers,
                    scheduler=scheduler, progress=progress, desc="clutter-scenes", unit="run")
    records: dict[str, dict[str, list[dict[str, Any]]]] = {
        s: {m: [] for m in methods} for s in scenes}
    errors: dict[str, str] = {}
    for j in jobs:
        if store.is_done(j):
            records[j.params["scene"]][j.params["method"]].append(store.load(j))
        else:
            errors[j.key] = store.error(j) or "not run"
    for by_method in records.values():
        for recs in by_method.values():
            recs.sort(key=lambda r: r["run"])
    pairs = study_pairs(methods)
    paired = {s: paired_comparisons(records[s], pairs) for s in scenes}
    if len(scenes) > 1:
        paired[POOLED] = paired_comparisons(pooled(records, runs), pairs)
    info = {"base": sc0.name, "scenes": list(scenes), "runs": runs, "seed": seed,
            "methods": list(methods), "tracker": TRACKER, **common,
            "params": {m: dict((params or {}).get(m, {})) for m in methods},
            "method_descriptions": {m: describe(m) for m in methods}}
    return ClutterScenesStudy(out_dir, info, records, errors, paired, done.computed,
                              done.skipped)
