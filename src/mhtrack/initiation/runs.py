"""Simulate → fuse → initiate over many seeds: what ``mhtrack cluster`` and ``mhtrack
initiate`` run. Returns raw per-scan / per-window outcomes; the metrics are computed from
them by :mod:`mhtrack.metrics.initiation` (this layer does not score).

Runs are independent: run ``r`` simulates with seed ``run_seeds(seed, runs)[r]``, drawn
from ``numpy.random.SeedSequence(seed)``; the random K-means of scan ``k`` in that run is
seeded with ``[run seed, k]``. The same ``seed`` always gives the same outcomes.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from tqdm.auto import tqdm

from mhtrack.initiation.fusion import AdaptiveKMeansFusion, FusedScan, KMeansFusion
from mhtrack.initiation.window import Window, sliding_windows
from mhtrack.records import Scan
from mhtrack.scenario import Scenario, simulate

CLUSTER_METHODS = ("adaptive", "random")


def run_seeds(seed: int, runs: int) -> list[int]:
    """``runs`` independent simulation seeds derived from ``seed``."""
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    if seed < 0:
        raise ValueError(f"seed must be >= 0, got {seed}")
    return [int(s) for s in np.random.SeedSequence(seed).generate_state(runs, np.uint32)]


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
    raise ValueError(f"unknown clustering method {method!r} (expected adaptive, random)")


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
    for rs in tqdm(run_seeds(seed, runs), desc=f"cluster {method}", unit="run",
                   disable=not progress, leave=False):
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


def fused_scans(scans: Sequence[Scan], fusion: str, *, run_seed: int = 0,
                weighting: str = "mean") -> tuple[list[Scan], list[float]]:
    """The scans fused by ``fusion`` (``"adaptive-kmeans"``, ``"kmeans"`` — the random
    K-means of :func:`fuse` — or ``"none"``) and the seconds spent on each."""
    if fusion == "none":
        return list(scans), [0.0] * len(scans)
    methods = {"adaptive-kmeans": "adaptive", "kmeans": "random"}
    if fusion not in methods:
        raise ValueError(f"unknown fusion {fusion!r} (expected adaptive-kmeans, kmeans, none)")
    out, secs = [], []
    for s in scans:
        t0 = time.perf_counter()
        out.append(fuse(s, methods[fusion], run_seed=run_seed, weighting=weighting).scan)
        secs.append(time.perf_counter() - t0)
    return out, secs


def run_initiation(scenario: Scenario, initiator: Any, *, fusion: str = "adaptive-kmeans",
                   runs: int = 1, seed: int = 0, weighting: str = "mean",
                   progress: bool = False) -> InitiationRun:
    """Simulate ``runs`` runs, fuse each scan, and run ``initiator`` (anything with
    ``n_scans`` and ``initiate(window)``) on every sliding window of ``n_scans`` scans."""
    windows: list[WindowOutcome] = []
    fusion_secs: list[float] = []
    N = initiator.n_scans
    for r, rs in enumerate(tqdm(run_seeds(seed, runs), desc="initiate", unit="run",
                                disable=not progress, leave=False)):
        raw = list(simulate(scenario, rs).plots.scans())
        fused, secs = fused_scans(raw, fusion, run_seed=rs, weighting=weighting)
        fusion_secs += secs
        for raw_win, win in zip(sliding_windows(raw, N), sliding_windows(fused, N),
                                strict=True):
            t0 = time.perf_counter()
            w = Window.from_scans(win)
            tracks = initiator.initiate(w)
            dt = time.perf_counter() - t0
            seen = np.concatenate([np.unique(s.origin[s.origin >= 0])  # type: ignore[index]
                                   for s in raw_win])
            ids, n_seen = np.unique(seen, return_counts=True)
            windows.append(WindowOutcome(r, w.scans, tracks.origins(w), ids, n_seen, dt))
    return InitiationRun(windows, fusion_secs, runs)
