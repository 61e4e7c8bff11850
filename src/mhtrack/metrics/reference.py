"""Our tracks scored against a reference system's tracks (an operational tracker's output),
the way surveillance evaluation tools do: the reference trajectories are the truth, and
both systems' trajectories are compared at common times (docs/metrics.md, "A reference
system as the truth").

* **Reference targets**: one per key (data source and track number); where a key's
  consecutive updates are more than ``max_gap_s`` apart the number is taken as reused and
  a new target starts.
* **Common times**: the reference's own update period ``T`` — the median positive interval
  between consecutive updates of a target, or the ``period_s`` given — from its first
  update on, ``t_k = t_0 + k·T`` (scan ``k``), up to its last update.
* **Sampling** (the same rule for the reference and for our tracks): at ``t_k`` a
  trajectory whose consecutive updates ``t_i ≤ t_k ≤ t_{i+1}`` are at most ``max_gap_s``
  apart is linearly interpolated between them,
  ``s(t_k) = s_i + (s_{i+1} − s_i)·(t_k − t_i)/(t_{i+1} − t_i)``, position and velocity;
  a trajectory exists from its first update to its last, never extrapolated; of updates
  at one time the last (in table order) is used.

Both tables then share their scans and are scored scan by scan
(:func:`~mhtrack.metrics.evaluate.evaluate` with ``at="scans"``): a track of ours where
the reference has none is a false track, a reference target without one of ours a miss.
Comparing the reference with itself gives zero error, and a trajectory exported as
CAT062 and read back differs from itself only by the items' LSBs (tests).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.metrics.evaluation import Evaluation
from mhtrack.records import NO_PLOT, TrackTable, TruthTable


def runs(key: np.ndarray, time: np.ndarray, max_gap_s: float) -> np.ndarray:
    """Trajectory index of each update: the updates of one key, cut where consecutive
    ones are more than ``max_gap_s`` apart; numbered in order of (key, first time)."""
    key, time = np.asarray(key, np.int64), np.asarray(time, float)
    order = np.lexsort((time, key))
    k, t = key[order], time[order]
    new = np.ones(k.size, bool)
    new[1:] = (k[1:] != k[:-1]) | (np.diff(t) > max_gap_s)
    out = np.empty(k.size, np.int64)
    out[order] = np.cumsum(new) - 1
    return out


def update_period(run: np.ndarray, time: np.ndarray) -> float | None:
    """Median positive interval between consecutive updates of one trajectory; ``None``
    when no trajectory has two updates at different times."""
    order = np.lexsort((time, run))
    same = run[order][1:] == run[order][:-1]
    dt = np.diff(np.asarray(time, float)[order])[same]
    dt = dt[dt > 0]
    return float(np.median(dt)) if dt.size else None


def sample(run: np.ndarray, time: np.ndarray, state: np.ndarray, t0: float,
           period: float, k_max: int) -> tuple[np.ndarray, ...]:
    """``(scan, run, x, y, vx, vy)`` of each trajectory (``run``) at ``t_0 + k·period``,
    ``0 ≤ k ≤ k_max``, linearly interpolated between its updates (module docstring);
    sorted by scan, then run."""
    order = np.lexsort((np.arange(time.size), time, run))
    rg, tt, st = run[order], np.asarray(time, float)[order], np.asarray(state)[order]
    starts = np.flatnonzero(np.r_[True, rg[1:] != rg[:-1]])
    parts: list[tuple[np.ndarray, ...]] = []
    eps = 1e-9 * max(1.0, period)
    for a, b in zip(starts, np.r_[starts[1:], rg.size], strict=True):
        last = np.r_[tt[a + 1:b] != tt[a:b - 1], True]  # the last of equal times
        t, s = tt[a:b][last], st[a:b][last]
        k0 = max(0, int(np.ceil((t[0] - t0 - eps) / period)))
        k1 = min(k_max, int(np.floor((t[-1] - t0 + eps) / period)))
        if k1 < k0:
            continue
        k = np.arange(k0, k1 + 1, dtype=np.int64)
        tk = np.clip(t0 + k * period, t[0], t[-1])
        parts.append((k, np.full(k.size, rg[a]),
                      *(np.interp(tk, t, s[:, j]) for j in range(4))))
    if not parts:
        return (np.zeros(0, np.int64), np.zeros(0, np.int64), *(np.zeros(0),) * 4)
    c = [np.concatenate(v) for v in zip(*parts, strict=True)]
    o = np.lexsort((c[1], c[0]))
    return tuple(v[o] for v in c)


def reference_truth(time: np.ndarray, key: np.ndarray, state: np.ndarray, *,
                    max_gap_s: float, period_s: float | None = None
                    ) -> tuple[TruthTable, float]:
    """The reference's updates (``time``, ``key``, ``state`` ``(n, 4)``) as the truth at
    the common times, and the period ``T`` used (module docstring). Target ids are the
    trajectory numbers of :func:`runs`."""
    time, state = np.asarray(time, float), np.asarray(state, float)
    if time.size == 0:
        raise ValueError("the reference has no track update")
    if not max_gap_s > 0:
        raise ValueError(f"max_gap_s must be > 0, got {max_gap_s!r}")
    run = runs(key, time, max_gap_s)
    period = update_period(run, time) if period_s is None else float(period_s)
    if period is None or not (np.isfinite(period) and period > 0):
        raise ValueError("no reference track has two updates at different times: give "
                         "the reference's update period")
    t0 = float(time.min())
    k_max = int(np.floor((float(time.max()) - t0) / period + 1e-9))
    scan, target, x, y, vx, vy = sample(run, time, state, t0, period, k_max)
    return TruthTable(scan=scan, time=t0 + scan * period, target_id=target, x=x, y=y,
                      vx=vx, vy=vy), period


def tracks_at_reference(tracks: TrackTable, truth: TruthTable, period: float, *,
                        max_gap_s: float) -> TrackTable:
    """Our ``tracks`` sampled at the reference truth's common times (``t_k = t_0 +
    k·period``, ``t_0`` its scan 0, up to its last scan) by the reference's rule; rows
    keep their ``track_id`` and use no plot (``plot`` −1: an interpolated state)."""
    if len(tracks) == 0 or len(truth) == 0:
        return TrackTable.empty()
    t0 = float(truth.time[0]) - int(truth.scan[0]) * period
    state = np.column_stack((tracks.x, tracks.y, tracks.vx, tracks.vy))
    run = runs(tracks.track_id, tracks.time, max_gap_s)
    scan, r, x, y, vx, vy = sample(run, tracks.time, state, t0, period,
                                   int(np.max(truth.scan)))
    first = np.zeros(int(run.max()) + 1, np.int64)
    first[run] = np.asarray(tracks.track_id, np.int64)
    return TrackTable(scan=scan, time=t0 + scan * period, track_id=first[r], x=x, y=y,
                      vx=vx, vy=vy, plot=np.full(scan.size, NO_PLOT)).sorted()


def evaluate_reference(tracks: TrackTable, time: np.ndarray, key: np.ndarray,
                       state: np.ndarray, *, max_gap_s: float,
                       period_s: float | None = None, **kwargs: Any
                       ) -> tuple[Evaluation, TruthTable, float]:
    """Score ``tracks`` against the reference updates (``time, key, state``): both
    sampled at the reference's common times, then
    :func:`~mhtrack.metrics.evaluate.evaluate` scan by scan (``kwargs``: its cut-off,
    order, matching distance, ...). Returns the evaluation, the reference truth and the
    period."""
    from mhtrack.metrics.evaluate import evaluate

    truth, period = reference_truth(time, key, state, max_gap_s=max_gap_s,
                                    period_s=period_s)
    ours = tracks_at_reference(tracks, truth, period, max_gap_s=max_gap_s)
    return evaluate(ours, truth, at="scans", **kwargs), truth, period
