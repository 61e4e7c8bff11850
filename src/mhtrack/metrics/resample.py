"""Tracks at the truth's times: aligning asynchronous tracker output with the truth.

A tracker fed with time-stamped plots of several rotating radars reports each track at the
times of its frames, not at the truth's sample times. :func:`tracks_at_times` turns such
output into one state per (track, truth time): the track's **latest state at or before**
the truth time ``t``, if it is **no older than** ``max_age_s``, predicted to ``t`` with
constant velocity (the tracker's own CV model, Bar-Shalom, Li & Kirubarajan 2001, §6.3.2):

    x(t) = x_k + vx_k · (t − t_k),     y(t) = y_k + vy_k · (t − t_k),     0 ≤ t − t_k ≤ max_age_s

:func:`alignment` decides whether tracks and truth already share their scans (then
:func:`~mhtrack.metrics.evaluate` aligns them on scan indices as it always did) or must be
resampled. Definitions: ``docs/metrics.md`` ("Asynchronous tracks").
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
import numpy.typing as npt

from mhtrack.records import NO_PLOT, PlotTable, TrackTable, TruthTable

#: Default largest age (s) of a track state used at a truth time: longer than the longest
#: rotation period of the shipped radars (12 s), so a track updated once per revolution is
#: never dropped between two looks, and short enough that a deleted track does not linger.
DEFAULT_MAX_AGE_S = 15.0

#: The two alignments of tracks on the truth (``evaluate(at=...)``).
ALIGNMENTS = ("scans", "truth-times")

Alignment = Literal["scans", "truth-times"]

_RTOL, _ATOL = 1e-6, 1e-9  # "same time" (as the CLI's check of two files of one run)


def check_max_age(value: float, name: str = "max_age_s") -> float:
    """A largest age: a number ``>= 0`` (``inf``: any age)."""
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a number >= 0 (seconds), got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number >= 0 (seconds), got {value!r}") from None
    if not v >= 0.0:  # also rejects NaN
        raise ValueError(f"{name} must be a number >= 0 (seconds), got {value!r}")
    return v


def truth_times(truth: TruthTable) -> tuple[np.ndarray, np.ndarray]:
    """``(scans, times)``: the truth's distinct scans (sorted) and each one's time (its
    first row's; the truth has one time per scan)."""
    scans, first = np.unique(np.asarray(truth.scan, np.int64), return_index=True)
    return scans, np.asarray(truth.time, np.float64)[first]


def is_synchronous(tracks: TrackTable, truth: TruthTable,
                   plots: PlotTable | None = None) -> bool:
    """Whether the tables share their scans: every track row whose scan the truth has is
    at the truth's time of that scan (relative 1e-6, absolute 1e-9 s), and the plots (when
    given) are not timed and agree with the truth the same way. Track rows at scans without
    truth do not decide (as in synchronous runs after the targets have gone)."""
    if plots is not None and plots.timed:
        return False
    scans, times = truth_times(truth)
    tables = [(tracks.scan, tracks.time)]
    if plots is not None:
        tables.append(plots.all_scan_times())
    for scan, time in tables:
        scan = np.asarray(scan, np.int64)
        if len(scans) == 0 or len(scan) == 0:
            continue
        pos = np.minimum(np.searchsorted(scans, scan), len(scans) - 1)
        shared = scans[pos] == scan
        t_row = np.asarray(time, np.float64)[shared]
        if not np.all(np.isclose(t_row, times[pos[shared]], rtol=_RTOL, atol=_ATOL)):
            return False
    return True


def alignment(tracks: TrackTable, truth: TruthTable, plots: PlotTable | None = None,
              at: str | None = None) -> Alignment:
    """The alignment ``evaluate`` uses: ``at`` when given (``"scans"`` or
    ``"truth-times"``), else ``"scans"`` when :func:`is_synchronous`, else
    ``"truth-times"``."""
    if at is None:
        return "scans" if is_synchronous(tracks, truth, plots) else "truth-times"
    if at not in ALIGNMENTS:
        raise ValueError(f"at must be one of {', '.join(map(repr, ALIGNMENTS))} or None, "
                         f"got {at!r}")
    return at  # type: ignore[return-value]


def tracks_at_times(tracks: TrackTable, times: npt.ArrayLike, scans: npt.ArrayLike,
                    max_age_s: float = DEFAULT_MAX_AGE_S) -> TrackTable:
    """One row per (track id, evaluation time ``t``) at which the track has a state no
    older than ``max_age_s``: its latest row with ``t_k ≤ t`` (the last such row in table
    order when several share ``t_k``), kept when ``t − t_k ≤ max_age_s`` and predicted to
    ``t`` with constant velocity, ``x + vx·(t − t_k)``, ``y + vy·(t − t_k)``.

    ``times`` and ``scans`` (same length) are the evaluation times and the scan index each
    output row gets (the truth's). Output rows: ``scan, time`` of the evaluation time,
    ``track_id, vx, vy, score, tentative`` of the source row, ``x, y`` predicted (the
    source's exactly when ``t = t_k``), ``plot`` the source's when ``t = t_k`` else ``-1``
    (a coasted state used no plot at ``t``), ``P`` dropped; sorted by scan then track id.
    Pure and vectorised: one merge sort of rows and queries, no loop over rows or tracks.
    """
    max_age = check_max_age(max_age_s)
    q_time = np.asarray(times, np.float64).ravel()
    q_scan = np.asarray(scans, np.int64).ravel()
    if len(q_time) != len(q_scan):
        raise ValueError(f"times and scans must have the same length, got {len(q_time)} "
                         f"and {len(q_scan)}")
    if not np.all(np.isfinite(q_time)):
        raise ValueError("times must be finite")
    if len(tracks) == 0 or len(q_time) == 0:
        return TrackTable.empty()
    r_time = np.asarray(tracks.time, np.float64)
    if not np.all(np.isfinite(r_time)):
        raise ValueError("tracks have non-finite times")
    ids = np.asarray(tracks.track_id, np.int64)
    uid, r_tid = np.unique(ids, return_inverse=True)
    q_order = np.argsort(q_time, kind="stable")
    qt = q_time[q_order]

    # Candidate queries of each track: times in [its first time, its last time + max_age],
    # the upper end widened by a few ulps: a query whose rounded t − t_k is ≤ max_age can
    # lie just above the rounded t_k + max_age; the test on dt below decides exactly.
    t_first = np.full(len(uid), np.inf)
    t_last = np.full(len(uid), -np.inf)
    np.minimum.at(t_first, r_tid, r_time)
    np.maximum.at(t_last, r_tid, r_time)
    lo = np.searchsorted(qt, t_first, side="left")
    if math.isfinite(max_age):
        slack = 4.0 * np.spacing(np.abs(t_last) + max_age)
        hi = np.searchsorted(qt, t_last + max_age + slack, side="right")
    else:
        hi = np.full(len(uid), len(qt))
    count = np.maximum(hi - lo, 0)
    c_tid = np.repeat(np.arange(len(uid)), count)
    c_q = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count - lo, count)
    if len(c_q) == 0:
        return TrackTable.empty()

    # Merge rows and candidate queries by (track, time, rows before queries, row order):
    # each query's latest row at or before it is the running last row of its track.
    n_r = len(r_time)
    m_tid = np.concatenate([r_tid, c_tid])
    m_time = np.concatenate([r_time, qt[c_q]])
    m_kind = np.concatenate([np.zeros(n_r, np.int8), np.ones(len(c_q), np.int8)])
    m_idx = np.concatenate([np.arange(n_r), np.arange(len(c_q))])
    order = np.lexsort((m_idx, m_kind, m_time, m_tid))
    is_row = m_kind[order] == 0
    last_pos = np.maximum.accumulate(np.where(is_row, np.arange(len(order)), -1))
    q_pos = np.flatnonzero(~is_row)
    src_pos = last_pos[q_pos]
    cand = m_idx[order[q_pos]]
    ok = src_pos >= 0
    src = np.where(ok, m_idx[order[np.maximum(src_pos, 0)]], 0)
    ok &= r_tid[src] == c_tid[cand]  # the latest row belongs to the same track
    src, cand = src[ok], cand[ok]
    q = q_order[c_q[cand]]
    dt = q_time[q] - r_time[src]
    keep = dt <= max_age
    src, q, dt = src[keep], q[keep], dt[keep]

    exact = dt == 0.0
    x = np.asarray(tracks.x, np.float64)[src]
    y = np.asarray(tracks.y, np.float64)[src]
    vx = np.asarray(tracks.vx, np.float64)[src]
    vy = np.asarray(tracks.vy, np.float64)[src]
    out = TrackTable(
        scan=q_scan[q],
        time=q_time[q],
        track_id=ids[src],
        x=np.where(exact, x, x + vx * dt),
        y=np.where(exact, y, y + vy * dt),
        vx=vx,
        vy=vy,
        plot=np.where(exact, np.asarray(tracks.plot, np.int64)[src], NO_PLOT),
        score=None if tracks.score is None else np.asarray(tracks.score)[src],
        P=None,
        tentative=None if tracks.tentative is None else np.asarray(tracks.tentative)[src],
    )
    return out.sorted()
