"""Tracks sent on a fixed period instead of on update (``docs/live.md``, *On a period*).

A surveillance display or a downstream system often wants every system track at fixed
instants — e.g. every 4 s — not each sector's tracks as the sector is stepped.
:class:`PeriodicSink` turns the frame-by-frame output into that, on the **data's time
axis** (not the wall clock), so the same input gives the same ticks every time:

* the ticks are ``τ_k = k · period`` on the sources' time axis (seconds since midnight
  UTC of the first day: every 4 s of UTC), from the first tick at or after the first
  frame's time;
* tick ``τ`` goes out when the first frame with a time after ``τ`` arrives — before that
  frame is applied — or at the end of the run for the ticks up to the last frame's time.
  Its rows are the **picture** after the last frame at or before ``τ``: every confirmed
  track of the tracker's best hypothesis (``picture(out)``, all radars' tracks, not only
  the frame's sector), each extrapolated from its own time ``t`` to ``τ`` by constant
  velocity: ``x(τ) = x + vx (τ − t)``, ``y(τ) = y + vy (τ − t)``, velocity kept;
  ``P`` is left out (the extrapolation adds the motion model's process noise, which a
  sink does not know). ``plot`` keeps the row of the track's last report (``-1``: it was
  coasting then), so CAT062's coasting flag means the same as on update;
* rows extrapolated by more than ``max_extrapolation_s`` (a track whose radar fell
  silent) are left out and counted (:attr:`stale`); a gap in the data longer than that
  emits no ticks (:attr:`skipped` counts them): the period output never invents a
  picture the data do not hold.

Each tick is handed to the downstream sinks as one :class:`~mhtrack.sinks.base.FrameOutput`
whose frame is an empty scan with ``index = k`` and ``time = τ`` (its rows' ``scan`` is
``k`` too), so any sink — CAT062 over UDP or to files, JSON lines — sends ticks unchanged.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.records import Scan, TrackTable
from mhtrack.sinks.base import FrameOutput, Sink

if TYPE_CHECKING:
    from mhtrack.sources.base import Source


def extrapolate(tracks: TrackTable, t: float, scan: int) -> TrackTable:
    """``tracks`` moved by constant velocity from each row's own time to ``t`` (module
    docstring: ``x + vx (t − time)``), ``time = t``, ``scan = scan``, without ``P``."""
    dt = t - tracks.time
    n = len(tracks)
    return dataclasses.replace(
        tracks, scan=np.full(n, int(scan), np.int64), time=np.full(n, float(t)),
        x=tracks.x + tracks.vx * dt, y=tracks.y + tracks.vy * dt, P=None)


def empty_frame(index: int, time: float) -> Scan:
    """A scan with no plots: the frame of a tick."""
    return Scan(index=int(index), time=float(time), z=np.zeros((0, 2)),
                sensor=np.zeros(0, np.int64), rows=np.zeros(0, np.int64))


class PeriodicSink(Sink):
    """Every ``period_s`` seconds of data time, the picture of all confirmed tracks
    extrapolated to the tick, to ``sinks`` (module docstring). ``picture(out)``: the
    confirmed tracks after frame ``out`` (each at its own time). ``next_tick``: the
    first tick's number (a resumed run continues its checkpoint's)."""

    def __init__(self, sinks: Sequence[Sink], period_s: float,
                 picture: Callable[[FrameOutput], TrackTable], *,
                 max_extrapolation_s: float | None = None,
                 next_tick: int | None = None) -> None:
        if not 0 < period_s < math.inf:
            raise ValueError(f"period must be > 0 s, got {period_s!r}")
        self.sinks, self.period_s, self.picture = list(sinks), float(period_s), picture
        self.max_extrapolation_s = (math.inf if max_extrapolation_s is None
                                    else float(max_extrapolation_s))
        #: Number of the next tick to send (``None`` until the first frame).
        self.next_tick = next_tick
        self.ticks = self.stale = self.skipped = 0
        self._now: TrackTable | None = None  # the picture after the last frame
        self._now_time = -math.inf

    def resume(self, picture: TrackTable, time: float) -> None:
        """Start from ``picture`` at ``time`` (a restarted run: its checkpoint's tracks),
        so the ticks before the first new frame go out from it."""
        self._now, self._now_time = picture, float(time)

    def start(self, source: Source | None) -> None:
        for s in self.sinks:
            s.start(source)

    def _due(self, until: float, inclusive: bool, stats: object) -> None:
        """Send every tick before ``until`` (``inclusive``: at it too) from the picture."""
        assert self.next_tick is not None
        while True:
            tau = self.next_tick * self.period_s
            if tau > until or (tau == until and not inclusive):
                return
            k = self.next_tick
            self.next_tick += 1
            if self._now is None or tau - self._now_time > self.max_extrapolation_s:
                self.skipped += 1
                continue
            fresh = tau - self._now.time <= self.max_extrapolation_s
            self.stale += int(np.count_nonzero(~fresh))
            rows = extrapolate(self._now.take(np.flatnonzero(fresh)), tau, k)
            tick = FrameOutput(empty_frame(k, tau), rows, TrackTable.empty(), stats)
            self.ticks += 1
            for s in self.sinks:
                s.write(tick)

    def write(self, out: FrameOutput) -> None:
        t = float(out.frame.time)
        if self.next_tick is None:
            self.next_tick = math.ceil(t / self.period_s)
        self._due(t, False, out.stats)
        self._now, self._now_time = self.picture(out), t

    def finish(self, stats: object = None) -> None:
        """Send the ticks up to the last frame's time (the end of the run)."""
        if self.next_tick is not None:
            self._due(self._now_time, True, stats)

    def close(self) -> None:
        self.finish()
        for s in self.sinks:
            s.close()

    def abort(self) -> None:
        for s in self.sinks:
            s.abort()
