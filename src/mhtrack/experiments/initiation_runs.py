"""Simulate → fuse → initiate over many seeds: what ``mhtrack cluster``, ``mhtrack
initiate`` and ``reproduce p2`` run. Returns raw per-scan / per-window outcomes; the
metrics are computed from them by :mod:`mhtrack.metrics.initiation` (this layer does not
score), the figures drawn by :mod:`mhtrack.plotting.initiation`.

Runs are independent: run ``r`` simulates with seed ``run_seed(seed, r, "words")``
(:mod:`mhtrack.experiments.jobs.seeds`); the random K-means of scan ``k`` in that run is
seeded with ``[run seed, k]``. The same ``seed`` always gives the same outcomes.

:func:`simulate_and_fuse` is the one simulate → fuse → window pipeline; everything else
here is built on it.
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mhtrack.build import INITIATION_FUSER_CLASSES, make_initiator
from mhtrack.experiments.jobs import run_seeds
from mhtrack.initiation.fused import FusedScan
from mhtrack.initiation.fusion import AdaptiveKMeansFusion, KMeansFusion
from mhtrack.initiation.window import Window, sliding_windows
from mhtrack.names import CLUSTER_METHODS, INITIATION_FUSIONS, INITIATORS
from mhtrack.progress import count
from mhtrack.records import Scan, TruthTable
from mhtrack.scenario import Scenario, simulate

#: Labels of the clustering methods in figures.
CLUSTER_NAMES = {"random": "K-means, random initial centres",
                 "adaptive": "adaptive K-means (P2 §1.2)"}


def n_targets_seen(scan: Scan) -> int:
    """Number of targets with at least one plot in ``scan`` (needs ``origin``)."""
    if scan.origin is None:
        raise ValueError("the scan's plots have no origin (needed to score)")
    return len(np.unique(scan.origin[scan.origin >= 0]))


def fuse(scan: Scan, method: str, *, run_seed: int = 0, weighting: str = "mean",
         **params: Any) -> FusedScan:
    """Fuse one scan: ``"adaptive"`` (:class:`AdaptiveKMeansFusion`) or ``"random"``
    (:class:`KMeansFusion` with ``k`` = the number of targets seen in the scan — an oracle
    ``k`` that favours the baseline, as P2 Fig. 2(a) — seeded with ``[run_seed, scan]``)."""
    if method == "adaptive":
        return AdaptiveKMeansFusion(weighting=weighting, **params).fuse(scan)
    if method == "random":
        k = max(n_targets_seen(scan), 1)
        return KMeansFusion(k, random_state=[run_seed, scan.index], weighting=weighting,
                            **params).fuse(scan)
    raise ValueError(f"unknown clustering method {method!r} (expected "
                     f"{', '.join(CLUSTER_METHODS)})")


def fused_scans(scans: Sequence[Scan], fusion: str, *, run_seed: int = 0,
                weighting: str = "mean", params: Mapping[str, Any] | None = None
                ) -> tuple[list[Scan], list[float]]:
    """The scans fused by ``fusion`` (``"adaptive-kmeans"``, ``"kmeans"`` — the random
    K-means of :func:`fuse` — or ``"none"``) and the seconds spent on each; ``params``
    are options of the fusion (e.g. P2's own steps only, ``reproduce p2
    --tracker-settings paper``)."""
    if fusion in INITIATION_FUSER_CLASSES and INITIATION_FUSER_CLASSES[fusion] is None:
        return list(scans), [0.0] * len(scans)
    methods = {"adaptive-kmeans": "adaptive", "kmeans": "random"}
    if fusion not in methods:
        raise ValueError(f"unknown fusion {fusion!r} (expected "
                         f"{', '.join(INITIATION_FUSIONS)})")
    out, secs = [], []
    for s in scans:
        t0 = time.perf_counter()
        out.append(fuse(s, methods[fusion], run_seed=run_seed, weighting=weighting,
                        **(params or {})).scan)
        secs.append(time.perf_counter() - t0)
    return out, secs


@dataclass(frozen=True)
class FusedRun:
    """One simulated run: its seed, truth, raw scans, fused scans and the seconds spent
    fusing each scan."""

    seed: int
    truth: TruthTable
    raw: list[Scan]
    fused: list[Scan]
    fusion_seconds: list[float]

    def windows(self, n_scans: int = 4) -> Iterator[tuple[list[Scan], list[Scan]]]:
        """``(raw, fused)`` scans of each sliding window of ``n_scans`` scans."""
        return zip(sliding_windows(self.raw, n_scans), sliding_windows(self.fused, n_scans),
                   strict=True)


def simulate_and_fuse(scenario: Scenario, run_seed: int, fusion: str = "adaptive-kmeans",
                      *, weighting: str = "mean", params: Mapping[str, Any] | None = None
                      ) -> FusedRun:
    """Simulate ``scenario`` with ``run_seed`` and fuse every scan with ``fusion``
    (options ``params``, :func:`fused_scans`)."""
    sim = simulate(scenario, run_seed)
    raw = list(sim.plots.scans())
    fused, secs = fused_scans(raw, fusion, run_seed=run_seed, weighting=weighting,
                              params=params)
    return FusedRun(run_seed, sim.truth, raw, fused, secs)


def targets_seen(raw_window: Sequence[Scan]) -> tuple[np.ndarray, np.ndarray]:
    """The targets seen in a window's raw scans and in how many of its scans."""
    seen = np.concatenate([np.unique(s.origin[s.origin >= 0])  # type: ignore[index]
                           for s in raw_window])
    ids, n_seen = np.unique(seen, return_counts=True)
    return ids, n_seen


def initiators(region: tuple[float, ...], *, theta_deg: float = 20.0,
               gate_radius: float = 300.0, v_min: float = 50.0, v_max: float = 400.0,
               extra: Mapping[str, Mapping[str, Any]] | None = None) -> dict[str, Any]:
    """Every initiator with ``mhtrack initiate``'s settings: the logic ones with the gate
    radius, the Hough ones with accumulators over ``region``; ``extra[method]`` are more
    constructor options of that method (a study's settings, e.g. ``accel_max``)."""
    out = {}
    for m in INITIATORS:
        p: dict[str, Any] = {"v_min": v_min, "v_max": v_max}
        if m.endswith("logic"):
            p["gate_radius"] = gate_radius
        else:
            p["region"] = region
        out[m] = make_initiator(m, theta_deg=theta_deg, **p, **(extra or {}).get(m, {}))
    return out


@dataclass(frozen=True)
class ClusteredScan:
    """One fused scan with what scoring needs: cluster labels of the input plots and
    their origins, the fused positions, the true positions of the targets seen, time."""

    scan: int
    labels: np.ndarray
    origin: np.ndarray
    fused: np.ndarray
    truth: np.ndarray
    seconds: float


def run_clustering(scenario: Scenario, method: str = "adaptive", *, runs: int = 1,
                   seed: int = 0, weighting: str = "mean", progress: bool = False,
                   **params: Any) -> list[ClusteredScan]:
    """Simulate ``runs`` runs of ``scenario`` and fuse every scan with ``method``."""
    out = []
    seeds = run_seeds(seed, runs, "words")
    for rs in count(len(seeds), f"cluster {method}", "run", progress).over(seeds):
        sim = simulate(scenario, rs)
        tr = sim.truth
        for scan in sim.plots.scans():
            t0 = time.perf_counter()
            f = fuse(scan, method, run_seed=rs, weighting=weighting, **params)
            dt = time.perf_counter() - t0
            seen = np.unique(scan.origin[scan.origin >= 0])  # type: ignore[index]
            at = (tr.scan == scan.index) & np.isin(tr.target_id, seen)
            out.append(ClusteredScan(scan.index, f.labels, scan.origin, f.scan.z,  # type: ignore[arg-type]
                                     tr.positions[at], dt))
    return out


@dataclass(frozen=True)
class WindowOutcome:
    """Tracks initiated in one window of one run.

    ``track_origins`` (n, N): origin of each track's plot per scan (−1 clutter, −2 none);
    ``target_ids``/``target_scans``: the targets seen in the window and in how many of its
    scans (from the raw plots, before fusion); ``seconds``: time to stack the window's
    fused scans and initiate (fusion excluded).
    """

    run: int
    scans: np.ndarray
    track_origins: np.ndarray
    target_ids: np.ndarray
    target_scans: np.ndarray
    seconds: float


@dataclass(frozen=True)
class InitiationRun:
    """All windows of all runs, and the time spent fusing (seconds per scan)."""

    windows: list[WindowOutcome]
    fusion_seconds: list[float]
    n_runs: int


def run_initiation(scenario: Scenario, initiator: Any, *, fusion: str = "adaptive-kmeans",
                   runs: int = 1, seed: int = 0, weighting: str = "mean",
                   progress: bool = False) -> InitiationRun:
    """Simulate ``runs`` runs, fuse each scan, and run ``initiator`` (anything with
    ``n_scans`` and ``initiate(window)``) on every sliding window of ``n_scans`` scans."""
    windows: list[WindowOutcome] = []
    fusion_secs: list[float] = []
    N = initiator.n_scans
    seeds = run_seeds(seed, runs, "words")
    for r, rs in enumerate(count(len(seeds), "initiate", "run", progress).over(seeds)):
        run = simulate_and_fuse(scenario, rs, fusion, weighting=weighting)
        fusion_secs += run.fusion_seconds
        for raw_win, win in run.windows(N):
            t0 = time.perf_counter()
            w = Window.from_scans(win)
            tracks = initiator.initiate(w)
            dt = time.perf_counter() - t0
            ids, n_seen = targets_seen(raw_win)
            windows.append(WindowOutcome(r, w.scans, tracks.origins(w), ids, n_seen, dt))
    return InitiationRun(windows, fusion_secs, runs)


# ---------------------------------------------------------------------------- one run's
# data for the figures of mhtrack.plotting.initiation (first run of a --seed)
@dataclass(frozen=True)
class ClusteringExample:
    """One scan of a run fused by each clustering method (``fused`` by label), with the
    truth positions at that scan."""

    scenario: str
    scan: Scan
    fused: Mapping[str, FusedScan]
    truth_xy: np.ndarray


def clustering_example(scenario: Scenario, seed: int, *, scan_number: int = 0,
                       adaptive_params: Mapping[str, Any] | None = None,
                       adaptive_label: str = CLUSTER_NAMES["adaptive"]) -> ClusteringExample:
    """Random vs adaptive K-means on scan ``scan_number`` of the first run of ``seed``;
    ``adaptive_params`` are the adaptive fusion's options, ``adaptive_label`` its name."""
    rs = run_seeds(seed, 1, "words")[0]
    sim = simulate(scenario, rs)
    scan = list(sim.plots.scans())[scan_number]
    fused = {CLUSTER_NAMES["random"]: fuse(scan, "random", run_seed=rs),
             adaptive_label: fuse(scan, "adaptive", run_seed=rs, **(adaptive_params or {}))}
    return ClusteringExample(scenario.name, scan, fused,
                             sim.truth.positions[np.isin(sim.truth.scan, [scan.index])])


@dataclass(frozen=True)
class InitiationExample:
    """One window of a run: its raw and fused plots, the tracks of each initiator on the
    fused window, the truth positions in the window's scans."""

    raw: Window
    fused: Window
    tracks: Mapping[str, Any]
    truth_xy: np.ndarray


def initiation_example(scenario: Scenario, seed: int, *, fusion: str = "adaptive-kmeans",
                       theta_deg: float = 20.0, window_number: int = 0,
                       gate_radius: float = 300.0, v_min: float = 50.0,
                       v_max: float = 400.0, methods: Sequence[str] = INITIATORS,
                       run: int = 0, fusion_params: Mapping[str, Any] | None = None,
                       initiator_params: Mapping[str, Mapping[str, Any]] | None = None,
                       ) -> InitiationExample:
    """Every initiator of ``methods`` on window ``window_number`` of run ``run`` of
    ``seed``, with the CLI's settings (Hough accumulators over the scenario's region),
    the fusion's options ``fusion_params`` and, per method, the initiator options
    ``initiator_params`` (a study's settings; :func:`initiators`' ``extra``)."""
    fr = simulate_and_fuse(scenario, run_seeds(seed, run + 1, "words")[run], fusion,
                           params=fusion_params)
    raw_win, win = list(fr.windows(4))[window_number]
    w = Window.from_scans(win)
    inits = initiators(scenario.region.as_tuple(), theta_deg=theta_deg,
                       gate_radius=gate_radius, v_min=v_min, v_max=v_max,
                       extra=initiator_params)
    tracks = {m: inits[m].initiate(w) for m in methods}
    return InitiationExample(Window.from_scans(raw_win), w, tracks,
                             fr.truth.positions[np.isin(fr.truth.scan, w.scans)])
