"""A self-contained version of P1 §3's ``crossing`` scenario with *uniform* Poisson
clutter (so the true clutter density is known exactly), and a truth-matching assessment
for the MHT tests."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.records import Scan

REGION = 4000.0  # the region is [-REGION, REGION]²
AREA = (2 * REGION) ** 2

#: crossing targets (P1 Table 1): initial [x, vx, y, vy] at their first scan, first, last scan.
CROSSING_TARGETS = (
    ((2000.0, -70.0, 3000.0, -60.0), 1, 80),
    ((-3000.0, 80.0, 2000.0, -100.0), 40, 90),
    ((-2000.0, 80.0, 3000.0, -100.0), 30, 90),
    ((3000.0, -70.0, 2000.0, -60.0), 1, 80),
)


@dataclass(frozen=True)
class Simulated:
    """Scans plus the truth: ``truth[k]`` maps target id → state at scan ``k``."""

    scans: list[Scan]
    truth: dict[int, dict[int, np.ndarray]]
    clutter_density: float


def simulate(
    targets=CROSSING_TARGETS,
    n_scans: int = 90,
    clutter_rate: float = 40.0,
    p_detection: float = 0.9,
    sigma: float = 100.0,
    seed: int = 0,
) -> Simulated:
    """Straight-line targets, ``T = 1`` s, plots with N(0, σ² I) noise detected with
    probability ``P_D``, Poisson(``clutter_rate``) clutter uniform over the region.
    Plot rows are numbered globally (as in a PlotTable)."""
    rng = np.random.default_rng(seed)
    scans, truth, row = [], {}, 0
    for k in range(1, n_scans + 1):
        z, origin = [], []
        truth[k] = {}
        for tid, (x0, first, last) in enumerate(targets):
            if not first <= k <= last:
                continue
            s = np.asarray(x0, float).copy()
            s[0] += s[1] * (k - first)
            s[2] += s[3] * (k - first)
            truth[k][tid] = s
            if rng.random() < p_detection:
                z.append(s[[0, 2]] + rng.normal(0, sigma, 2))
                origin.append(tid)
        nc = rng.poisson(clutter_rate)
        z.extend(rng.uniform(-REGION, REGION, (nc, 2)))
        origin.extend([-1] * nc)
        z = np.asarray(z, float).reshape(-1, 2)
        perm = rng.permutation(len(z))
        n = len(z)
        scans.append(
            Scan(
                index=k,
                time=float(k),
                z=z[perm],
                sensor=np.zeros(n, np.int64),
                rows=np.arange(row, row + n, dtype=np.int64),
                origin=np.asarray(origin, np.int64)[perm],
            )
        )
        row += n
    return Simulated(scans, truth, clutter_rate / AREA)


def random_targets(n: int, n_scans: int, seed: int):
    """``n`` targets inside the region moving at 50–250 m/s, alive all scans."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        p = rng.uniform(-0.6 * REGION, 0.6 * REGION, 2)
        speed, head = rng.uniform(50, 250), rng.uniform(0, 2 * np.pi)
        v = speed * np.array([np.cos(head), np.sin(head)])
        out.append(((p[0], v[0], p[1], v[1]), 1, n_scans))
    return tuple(out)


@dataclass(frozen=True)
class Assessment:
    """How a tracker's output matches the truth (nearest target within ``radius``).

    ``first_confirmed[t]``: first scan target ``t`` is reported; ``owner[track]``: the
    target a track follows on most of its rows (-1: none, a false track);
    ``false_lengths``: rows of each false track; ``errors``: position errors of rows of
    true tracks that are within ``radius`` of their target; ``switches``: rows where a
    true track is nearest another target than its owner while its owner is alive.
    """

    first_confirmed: dict[int, int]
    owner: dict[int, int]
    tracks_of: dict[int, list[int]]
    false_lengths: dict[int, int]
    errors: np.ndarray
    switches: int


def assess(sim: Simulated, out, radius: float = 400.0) -> Assessment:
    near: dict[int, list[int]] = {}
    rows_err: dict[int, list[float]] = {}
    for i in range(len(out)):
        k, tr = int(out.scan[i]), int(out.track_id[i])
        p = np.array([out.x[i], out.y[i]])
        best, bd = -1, np.inf
        for t, s in sorted(sim.truth.get(k, {}).items()):
            d = float(np.hypot(*(p - s[[0, 2]])))
            if d < bd:
                best, bd = t, d
        near.setdefault(tr, []).append(best if bd <= radius else -1)
        rows_err.setdefault(tr, []).append(bd)
    owner, false_lengths, tracks_of, errs, switches = {}, {}, {}, [], 0
    first: dict[int, int] = {}
    for tr, ts in near.items():
        vals, counts = np.unique(ts, return_counts=True)
        o = int(vals[np.argmax(counts)])
        owner[tr] = o
        if o < 0:
            false_lengths[tr] = len(ts)
            continue
        tracks_of.setdefault(o, []).append(tr)
        for t, e in zip(ts, rows_err[tr], strict=True):
            if t == o:
                errs.append(e)
            elif t >= 0:
                switches += 1
    for i in range(len(out)):
        tr = int(out.track_id[i])
        o = owner[tr]
        if o >= 0:
            first.setdefault(o, int(out.scan[i]))
    return Assessment(first, owner, tracks_of, false_lengths, np.asarray(errs), switches)


def same_tracks(a, b) -> bool:
    """Two TrackTables equal column by column, bit for bit (absent columns equal absent)."""
    return len(a) == len(b) and all(
        np.array_equal(getattr(a, f), getattr(b, f)) for f in type(a).__dataclass_fields__)
