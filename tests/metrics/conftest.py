"""Builders shared by the metrics tests (exposed as fixtures: ``--import-mode=importlib``)."""

from collections.abc import Callable

import numpy as np
import pytest

from mhtrack.records import TrackTable, TruthTable


def _truth(rows: list[tuple[int, int, float, float]]) -> TruthTable:
    """Truth table from ``(scan, target_id, x, y)`` rows (velocities zero, time = scan)."""
    a = np.array(rows, dtype=np.float64).reshape(-1, 4)
    a = a[np.lexsort((a[:, 1], a[:, 0]))]
    z = np.zeros(len(a))
    scan = a[:, 0].astype(np.int64)
    return TruthTable(scan, scan.astype(float), a[:, 1].astype(np.int64), a[:, 2], a[:, 3], z, z)


def _tracks(rows: list[tuple[int, int, float, float]]) -> TrackTable:
    """Track table from ``(scan, track_id, x, y)`` rows (no plot, velocities zero)."""
    a = np.array(rows, dtype=np.float64).reshape(-1, 4)
    a = a[np.lexsort((a[:, 1], a[:, 0]))]
    z = np.zeros(len(a))
    scan = a[:, 0].astype(np.int64)
    return TrackTable(
        scan,
        scan.astype(float),
        a[:, 1].astype(np.int64),
        a[:, 2],
        a[:, 3],
        z,
        z,
        np.full(len(a), -1, np.int64),
    )


def _random_run(
    seed: int, *, n_targets: int = 6, n_scans: int = 40, noise: float = 120.0
) -> tuple[TruthTable, TrackTable]:
    """A random run that exercises every CLEAR-MOT event.

    Targets are born and die at random scans and move in a 3 km square (so that tracks are
    often within a few hundred metres of several targets). Each target is followed by a
    track with Gaussian position noise ``noise`` (m) that drops out (10 %), is replaced by a
    new id (5 %), or swaps id with another target's track (4 %); false tracks appear at
    random (Poisson mean 0.4 per scan, some persisting a few scans).
    """
    rng = np.random.default_rng(seed)
    birth = rng.integers(0, n_scans // 2, n_targets)
    death = rng.integers(n_scans // 2, n_scans + 1, n_targets)
    start = rng.uniform(0, 3000, (n_targets, 2))
    vel = rng.normal(0, 25, (n_targets, 2))
    track_of = np.arange(n_targets) + 100  # current track id following each target
    next_id = 1000
    truth_rows, track_rows = [], []
    false_tracks: list[list[float]] = []  # [id, x, y, scans left]
    for k in range(n_scans):
        alive = np.flatnonzero((birth <= k) & (k < death))
        pos = start + vel * k
        if len(alive) >= 2 and rng.random() < 0.04 * len(alive):
            a, b = rng.choice(alive, 2, replace=False)
            track_of[[a, b]] = track_of[[b, a]]
        for t in alive:
            truth_rows.append((k, t, *pos[t]))
            u = rng.random()
            if u < 0.05:
                track_of[t] = next_id
                next_id += 1
            if u > 0.10:
                track_rows.append((k, track_of[t], *(pos[t] + rng.normal(0, noise, 2))))
        for _ in range(rng.poisson(0.4)):
            false_tracks.append([next_id, *rng.uniform(0, 3000, 2), rng.integers(1, 5)])
            next_id += 1
        for f in false_tracks:
            track_rows.append((k, int(f[0]), f[1] + rng.normal(0, 30), f[2] + rng.normal(0, 30)))
            f[3] -= 1
        false_tracks = [f for f in false_tracks if f[3] > 0]
    return _truth(truth_rows), _tracks(track_rows)


@pytest.fixture
def make_truth() -> Callable[..., TruthTable]:
    return _truth


@pytest.fixture
def make_tracks() -> Callable[..., TrackTable]:
    return _tracks


@pytest.fixture
def random_run() -> Callable[..., tuple[TruthTable, TrackTable]]:
    return _random_run
