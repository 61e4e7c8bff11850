"""The smoothed history: every track's rows smoothed over the whole track.

:class:`SmoothedHistory` sits in front of other sinks (a tracks file, a CAT062 file,
a collector). It keeps the history rows (online rows and backfill) with their filtered
model states (:attr:`MHTTracker.keep_models <mhtrack.mht.MHTTracker.keep_models>`),
and when the run ends smooths each track over all of its rows —
fixed-interval Rauch–Tung–Striebel, Kim's IMM form for an IMM
(:mod:`mhtrack.models.smoother`) — then hands the sinks it wraps the smoothed rows as one
output, and closes them. Positions, velocities and ``P`` are the smoothed ones; every
other column (scan, time, track id, plot, score, tentative, attributes) is the row's own.
The online view is not smoothed: it is what the tracker reported, frame by frame.

A row can be smoothed over the rest of its track only once the track has ended; to keep
memory bounded on long recordings a row is final, and smoothed over the rows of its track
that have arrived, once they reach :data:`SMOOTHING_LAG_S` past it (10 minutes: longer
than the smoother's reach by far — the rows' difference from the whole-track answer is
in ``docs/mht.md``). The rows held take about 0.55 kB each with a two-model IMM.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.attributes import accuracy
from mhtrack.models.smoother import Filtered, smooth
from mhtrack.records import TrackTable
from mhtrack.sinks.base import FrameOutput, Sink

if TYPE_CHECKING:
    from mhtrack.models.motion import MotionModel
    from mhtrack.sources.base import Source


def smoothed_rows(rows: TrackTable, motion: MotionModel) -> TrackTable:
    """``rows`` (a run's history, any order) with ``x, y, vx, vy, P`` smoothed track by
    track (:func:`~mhtrack.models.smoother.smooth`; an IMM needs the rows' ``mu, xm,
    Pm``) and the attributes' accuracy that of the smoothed ``P``
    (:func:`~mhtrack.attributes.accuracy`), the model states dropped; the same order and
    every other column kept."""
    if len(rows) == 0:
        return dataclasses.replace(rows, mu=None, xm=None, Pm=None)
    if rows.P is None:
        raise ValueError("smoothing needs each row's covariance P")
    x = np.column_stack((rows.x, rows.vx, rows.y, rows.vy))  # the state [x, vx, y, vy]
    xs, Ps = smooth(Filtered(rows.track_id, rows.time, x, rows.P, rows.mu, rows.xm,
                             rows.Pm), motion)
    attrs = rows.attrs
    if attrs is not None:  # the position's accuracy is that of the smoothed covariance
        attrs = dataclasses.replace(attrs, **dict(zip(
            ("sigma_major", "sigma_minor", "sigma_orient"), accuracy(Ps), strict=True)))
    return dataclasses.replace(rows, x=xs[:, 0].copy(), vx=xs[:, 1].copy(),
                               y=xs[:, 2].copy(), vy=xs[:, 3].copy(), P=Ps, attrs=attrs,
                               mu=None, xm=None, Pm=None)


#: A history row is final, and smoothed, once the track's rows reach this much data time
#: past it (s), or its track has ended: the smoothing lag (module docstring).
SMOOTHING_LAG_S = 600.0


class SmoothedHistory(Sink):
    """The history rows of a run, smoothed track by track, into ``sinks`` (module
    docstring); ``motion``: the tracker's motion model (``MHTTracker.motion``; the
    tracker must keep its rows' model states, ``keep_models``, when it is an IMM).

    A row is held until it is final: no backfill can come before it (its scan below
    :attr:`FrameOutput.settled`) and the rows seen reach ``lag_s`` of data time past it.
    Every ``lag_s / 4`` of data time the tracks with final rows are smoothed over all
    the rows held of them and their final rows handed on (with ``settled``: the oldest
    scan still held), so memory holds about ``1.25 lag_s`` of rows. A row whose track
    ends within ``lag_s`` after it is smoothed over the whole rest of its track (the
    fixed-interval smoother, exactly); a longer track's row over the next ``lag_s`` to
    ``1.25 lag_s`` of it (fixed-lag). ``lag_s = inf``: every row at the end."""

    def __init__(self, sinks: Sequence[Sink], motion: MotionModel,
                 lag_s: float = SMOOTHING_LAG_S) -> None:
        if not lag_s > 0:
            raise ValueError(f"the smoothing lag must be > 0 s, got {lag_s}")
        self.sinks, self.motion, self.lag_s = list(sinks), motion, float(lag_s)
        self._held: list[TrackTable] = []
        self._t = -np.inf  # the latest row time seen
        self._t_pass = -np.inf  # the data time of the last release
        self._last: FrameOutput | None = None

    def start(self, source: Source | None) -> None:
        for s in self.sinks:
            s.start(source)

    def write(self, out: FrameOutput) -> None:
        self._last = out
        for rows in (out.online, out.backfill):
            if rows is not None and len(rows):
                self._held.append(rows)
                self._t = max(self._t, float(rows.time.max()))
        if out.settled is not None and self._t - self._t_pass >= self.lag_s / 4:
            self._t_pass = self._t
            self._release(out, self._t - self.lag_s, out.settled)

    def _release(self, out: FrameOutput, before: float, settled: int | None) -> None:
        """Smooth the tracks with final rows (time ≤ ``before``, scan below ``settled``;
        ``settled`` None: every row) and hand those rows on."""
        if not self._held:
            return
        held = TrackTable.concat(self._held)
        final = held.time <= before
        if settled is not None:
            final &= held.scan < settled
        if not final.any():
            self._held = [held]
            return
        mine = np.isin(held.track_id, np.unique(held.track_id[final]))
        rows = smoothed_rows(held.take(mine), self.motion).take(final[mine])
        rest = held.take(~final)
        self._held = [rest] if len(rest) else []
        if settled is not None and len(rest):
            settled = min(settled, int(rest.scan.min()))
        done = FrameOutput(out.frame, rows, TrackTable.empty(), out.stats, settled)
        for s in self.sinks:
            s.write(done)

    def close(self) -> None:
        if self._last is not None:
            self._release(self._last, np.inf, None)
        self._held = []
        for s in self.sinks:
            s.close()

    def abort(self) -> None:
        self._held = []
        for s in self.sinks:
            s.abort()
