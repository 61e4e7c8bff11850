"""Health and latency of a live run (``docs/live.md``, *Health and latency*): counts,
rates, tracks, silent radars and the latency of each sector, as one status line, a JSON
object and Prometheus text.

**Latency** of a frame (a sector: one radar's plots over at most an eighth of its
rotation) is ``t_out − t_in``: ``t_in`` the receive time of the frame's **last
datagram** — the one carrying the frame's plot decoded last — and ``t_out`` the time its
output had gone to every sink (the CAT062 datagrams sent, the JSON lines written). It
includes the wait for the re-order window and for the next plot that closes the frame
(``docs/sources.md``): what a consumer sees. Frames made by the end of the input (a stop:
the window and the open frames flushed) are timed by the stop, not by the data: they
are counted apart (``after_end``) and left out. Receive times come from the reader thread
(``time.time()`` when ``recv`` returned); :class:`Arrivals` maps each plot's
decoding-order number to its datagram's receive time over a bounded horizon.

The **percentiles** p50/p99 are numpy's ``percentile`` (linear interpolation between
order statistics, Hyndman & Fan's definition 7) of the latencies of the frames since the
last status line (the line) or of the last :data:`WINDOW` frames (:meth:`Health.snapshot`,
the JSON and Prometheus summary, the run's end).

A radar is **silent** when the stream's time has run more than
:data:`SILENT_PERIODS` of its rotation periods past its last frame (or past the run's
first frame, if it never sent one) — on the data's time axis, so a silence shows once
another radar's plots move the clock on.
"""

from __future__ import annotations

import bisect
import math
import threading
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from mhtrack.sinks.base import FrameOutput, Sink

#: Latencies kept for the snapshot's percentiles (the last frames).
WINDOW = 100_000
#: Datagrams remembered by :class:`Arrivals` at most (4 MB; at the national load's
#: 1 400 datagrams/s, the last 187 s: a frame's plots are decoded within the re-order
#: window and a frame's length of it going out).
MAX_ARRIVALS = 1 << 18
#: A radar is silent after this many rotation periods without a frame.
SILENT_PERIODS = 3.0


class Arrivals:
    """Receive time of the datagram of each plot, by the plot's decoding-order number:
    :meth:`add` ``(first plot number of the datagram, receive time)`` as each datagram
    is taken (plots of earlier datagrams all numbered below it); :meth:`time_of` a
    plot. The last ``keep`` datagrams are remembered, in two NumPy rings allocated (and
    written) whole at the start — memory flat from the first datagram; older plots have
    no time."""

    def __init__(self, keep: int = MAX_ARRIVALS) -> None:
        if keep < 1:
            raise ValueError(f"keep must be >= 1 datagram, got {keep!r}")
        self.keep = int(keep)
        self._first = np.full(self.keep, -1, np.int64)
        self._time = np.full(self.keep, np.nan)
        self.n = 0  # datagrams added

    def add(self, first_plot: int, when: float) -> None:
        i = self.n % self.keep
        self._first[i] = first_plot
        self._time[i] = when
        self.n += 1

    def time_of(self, plot: int) -> float | None:
        """The receive time of the datagram holding plot ``plot`` (the last datagram
        taken whose first plot number is at most ``plot``); ``None`` if forgotten."""
        lo, keep, first = max(0, self.n - self.keep), self.keep, self._first
        i = bisect.bisect_right(range(lo, self.n), int(plot),
                                key=lambda j: int(first[j % keep])) - 1
        return None if i < 0 else float(self._time[(lo + i) % keep])


def percentiles(values: list[float] | np.ndarray, qs: tuple[float, ...] = (50, 99)
                ) -> tuple[float, ...]:
    """``numpy.percentile`` (linear) of ``values`` at ``qs``; NaN for none."""
    v = np.asarray(values, float)
    if v.size == 0:
        return tuple(math.nan for _ in qs)
    return tuple(float(x) for x in np.percentile(v, qs))


class Health(Sink):
    """Counts what a live run did and times each frame (module docstring). Put it
    *after* the output sinks, so its ``write`` comes once the frame has gone out.

    ``counts()`` → the running totals ``datagrams, queue_drops, kernel_drops, plots,
    duplicates, late_drops`` (``kernel_drops`` ``None`` where not counted; callables of
    the reader and source); ``tracks()`` → confirmed tracks
    after a frame (called in :meth:`write`, the stepping thread); ``plot_numbers(out)``
    → the frame's plots' decoding-order numbers; ``periods``
    — each radar's rotation period (s); ``clock`` → now (s, the receive times' clock)."""

    def __init__(self, counts: Callable[[], Mapping[str, int | None]],
                 tracks: Callable[[], int],
                 plot_numbers: Callable[[FrameOutput], np.ndarray],
                 periods: Mapping[int, float], clock: Callable[[], float], *,
                 arrivals: Arrivals | None = None, window: int = WINDOW) -> None:
        self.counts, self.tracks, self.plot_numbers = counts, tracks, plot_numbers
        self.periods = dict(periods)
        self.clock = clock
        self.arrivals = Arrivals() if arrivals is None else arrivals
        self.frames = self.n_tracks = 0
        #: Set once the input has ended: later frames are those the end made (the
        #: re-order window and open frames flushed), timed by the stop, not by the
        #: data — counted in :attr:`after_end`, left out of the latencies.
        self.input_ended = False
        self.after_end = 0
        self._lock = threading.Lock()  # write (stepping) against snapshot (status thread)
        self.untimed = 0  # frames whose last datagram was forgotten
        self.latency_sum = 0.0
        self.latency_count = 0
        #: The last ``window`` latencies: a ring allocated (and written) whole at the
        #: start, so the memory does not grow with the frames.
        self.recent = np.full(int(window), np.nan)
        self._n_recent = 0
        self._interval: list[float] = []
        self._last_frame: dict[int, float] = {}  # radar -> time of its last frame
        self._first_time: float | None = None
        self._stream_time = -math.inf
        self._last_line: tuple[float, int, int] | None = None

    def write(self, out: FrameOutput) -> None:
        now = self.clock()
        n_tracks = int(self.tracks())
        with self._lock:
            self._write(out, now, n_tracks)

    def _write(self, out: FrameOutput, now: float, n_tracks: int) -> None:
        self.frames += 1
        self.n_tracks = n_tracks
        t = float(out.frame.time)
        self._first_time = t if self._first_time is None else self._first_time
        self._stream_time = max(self._stream_time, t)
        for s in np.unique(out.frame.sensor).tolist():
            self._last_frame[int(s)] = t
        plots = self.plot_numbers(out)
        if self.input_ended:
            self.after_end += 1
            return
        if plots.size == 0:
            return
        t_in = self.arrivals.time_of(int(plots.max()))
        if t_in is None:
            self.untimed += 1
            return
        self._observe(now - t_in)

    def observe(self, latency_s: float) -> None:
        """One frame's latency (s)."""
        with self._lock:
            self._observe(latency_s)

    def _observe(self, latency_s: float) -> None:
        self.latency_sum += latency_s
        self.latency_count += 1
        self.recent[self._n_recent % self.recent.size] = latency_s
        self._n_recent += 1
        self._interval.append(latency_s)

    def silent(self) -> list[int]:
        """The radars silent now (module docstring), by id."""
        if self._first_time is None:
            return []
        return sorted(sid for sid, p in self.periods.items()
                      if self._stream_time - self._last_frame.get(sid, self._first_time)
                      > SILENT_PERIODS * p)

    def snapshot(self, now: float | None = None) -> dict[str, Any]:
        """Every figure now, JSON-able: the totals, ``frames, tracks, radars_silent``
        (ids), ``latency_s`` — ``p50, p99`` of the last :data:`WINDOW` frames, ``sum``
        and ``count`` of all — and ``time`` (the clock)."""
        with self._lock:
            p50, p99 = percentiles(self.recent[:min(self._n_recent, self.recent.size)])
            return {"time": self.clock() if now is None else now, **dict(self.counts()),
                    "frames": self.frames, "tracks": self.n_tracks,
                    "radars_silent": self.silent(),
                    "latency_s": {"p50": p50, "p99": p99, "sum": self.latency_sum,
                                  "count": self.latency_count, "untimed": self.untimed,
                                  "after_end": self.after_end}}

    def line(self, snap: Mapping[str, Any] | None = None) -> str:
        """The status line: rates since the last line (none at the first), totals, and
        the latency percentiles of the frames since the last line."""
        s = self.snapshot() if snap is None else snap
        now, d, p = s["time"], s["datagrams"], s["plots"]
        rates = ""
        if self._last_line is not None and now > self._last_line[0]:
            dt = now - self._last_line[0]
            rates = (f"{(d - self._last_line[1]) / dt:.1f} datagrams/s, "
                     f"{(p - self._last_line[2]) / dt:.1f} plots/s, ")
        self._last_line = (now, d, p)
        with self._lock:
            interval, self._interval = self._interval, []
        p50, p99 = percentiles(interval)
        lat = ("" if math.isnan(p50) else
               f", latency p50 {1e3 * p50:.0f} ms p99 {1e3 * p99:.0f} ms")
        silent = s["radars_silent"]
        kernel = s.get("kernel_drops")  # None: not counted (SO_RXQ_OVFL is Linux's)
        kernel = "kernel drops n/a" if kernel is None else f"{kernel} kernel drops"
        return (f"live: {rates}{d} datagrams, {p} plots, {s['duplicates']} duplicates, "
                f"{s['late_drops']} late drops, {s['queue_drops']} queue drops, "
                f"{kernel}, "
                f"{s['frames']} frames, {s['tracks']} tracks, {len(silent)} radars silent"
                f"{' (' + ', '.join(map(str, silent)) + ')' if silent else ''}{lat}")
