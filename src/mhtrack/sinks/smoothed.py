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

A row is final only when its track has ended, so this sink keeps the run's history rows
in memory (each with ``r`` model states) until the end: about 0.35 kB a row with a
two-model IMM.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.models.smoother import Filtered, smooth
from mhtrack.records import TrackTable
from mhtrack.sinks.base import FrameOutput, Sink, TrackCollector

if TYPE_CHECKING:
    from mhtrack.models.motion import MotionModel
    from mhtrack.sources.base import Source


def smoothed_rows(rows: TrackTable, motion: MotionModel) -> TrackTable:
    """``rows`` (a run's history, any order) with ``x, y, vx, vy, P`` smoothed track by
    track (:func:`~mhtrack.models.smoother.smooth`; an IMM needs the rows' ``mu, xm,
    Pm``), the model states dropped; the same order and every other column kept."""
    if len(rows) == 0:
        return dataclasses.replace(rows, mu=None, xm=None, Pm=None)
    if rows.P is None:
        raise ValueError("smoothing needs each row's covariance P")
    x = np.column_stack((rows.x, rows.vx, rows.y, rows.vy))  # the state [x, vx, y, vy]
    xs, Ps = smooth(Filtered(rows.track_id, rows.time, x, rows.P, rows.mu, rows.xm,
                             rows.Pm), motion)
    return dataclasses.replace(rows, x=xs[:, 0].copy(), vx=xs[:, 1].copy(),
                               y=xs[:, 2].copy(), vy=xs[:, 3].copy(), P=Ps,
                               mu=None, xm=None, Pm=None)


class SmoothedHistory(Sink):
    """The history rows of a run, smoothed at its end, into ``sinks`` (module docstring);
    ``motion``: the tracker's motion model (``MHTTracker.motion``). The tracker must keep
    its rows' model states (``keep_models``) when ``motion`` is an IMM."""

    def __init__(self, sinks: Sequence[Sink], motion: MotionModel) -> None:
        self.sinks, self.motion = list(sinks), motion
        self._rows = TrackCollector("history")
        self._last: FrameOutput | None = None

    def start(self, source: Source | None) -> None:
        for s in self.sinks:
            s.start(source)

    def write(self, out: FrameOutput) -> None:
        self._rows.write(out)
        self._last = out

    def smoothed(self) -> TrackTable:
        """The rows so far, smoothed (sorted by scan, then track id)."""
        return smoothed_rows(self._rows.tracks(), self.motion)

    def close(self) -> None:
        rows = self.smoothed()
        self._rows.clear()
        if self._last is not None:
            last = self._last
            out = FrameOutput(last.frame, rows, TrackTable.empty(), last.stats, None)
            for s in self.sinks:
                s.write(out)
        for s in self.sinks:
            s.close()

    def abort(self) -> None:
        for s in self.sinks:
            s.abort()
