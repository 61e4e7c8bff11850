"""Health and latency of a live run (``docs/live.md``, *Health and latency*): counts,
rates, tracks, silent radars and the latency of each sector, as one status line, a JSON
object and Prometheus text.

**Latency** of a frame (a sector: one radar's plots over at most an eighth of its
rotation, or between two of its CAT034 crossings) is ``t_out − t_in``: ``t_in`` the
receive time of the frame's **last datagram** — the one carrying the frame's plot
decoded last, or, for a frame closed by its radar's sector crossing (``Scan.closing``,
``live --sector-frames``), the one carrying that crossing if it came later: the sector's
last datagram — and ``t_out`` the time its output had gone to every sink (the CAT062
datagrams sent, the JSON lines written). It includes the wait for the re-order window
and, for a frame closed otherwise, for the next plot that closes it (``docs/sources.md``):
what a consumer sees. The former measure — from the last plot's datagram alone — is
kept beside it (``last_plot`` in :meth:`Health.snapshot`). Frames made by the end of
the input (a stop: the window and the open frames flushed) are timed by the stop, not
by the data: they are counted apart (``after_end``) and left out. A frame whose
datagram (or crossing's) is forgotten is counted in ``untimed``. The plots a resumed
run took back from its checkpoint (``file_row`` -1) came before the restart, earlier
than any datagram since: a frame of them alone is timed from its closing crossing if
that came since (the sector's last datagram), else — closed by a crossing held in the
checkpoint too, or by anything else — it is timed by the restart, not by the data, and
counted apart (``restored``), as ``after_end``. Receive times come
from the reader thread (``time.time()`` when ``recv`` returned); :class:`Arrivals` maps
each plot's decoding-order number, and each byte offset of the input, to its datagram's
receive time over a bounded horizon.

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
#: The counts of what came too late for the re-order window: plots, and (sector frames)
#: sweep marks; the run's summary line names each when there are any (``LiveResult``).
LATE = ("late_drops", "late_crossings")


class Arrivals:
    """Receive time of the datagram of each plot, by the plot's decoding-order number:
    :meth:`add` ``(first plot number of the datagram, receive time, its size)`` as each
    datagram is taken (plots of earlier datagrams all numbered below it); :meth:`time_of`
    a plot, :meth:`time_at` a byte offset in the input (the datagrams' bytes end to end,
    as the source counts them: a sweep mark's ``offset``). The last ``keep`` datagrams
    are remembered, in NumPy rings allocated (and written) whole at the start — memory
    flat from the first datagram; older plots have no time."""

    def __init__(self, keep: int = MAX_ARRIVALS) -> None:
        if keep < 1:
            raise ValueError(f"keep must be >= 1 datagram, got {keep!r}")
        self.keep = int(keep)
        self._first = np.full(self.keep, -1, np.int64)
        self._time = np.full(self.keep, np.nan)
        self._start = np.full(self.keep, -1, np.int64)  # each datagram's first byte
        self.n = 0  # datagrams added
        self.bytes = 0  # their sizes' sum

    def add(self, first_plot: int, when: float, size: int = 0) -> None:
        i = self.n % self.keep
        self._first[i] = first_plot
        self._time[i] = when
        self._start[i] = self.bytes
        self.n += 1
        self.bytes += int(size)

    def time_at(self, offset: int) -> float | None:
        """The receive time of the datagram holding byte ``offset`` (the last datagram
        taken that starts at or before it); ``None`` if forgotten or not yet taken."""
        lo, keep, start = max(0, self.n - self.keep), self.keep, self._start
        if offset < 0 or offset >= self.bytes:
            return None
        i = bisect.bisect_right(range(lo, self.n), int(offset),
                                key=lambda j: int(start[j % keep])) - 1
        return None if i < 0 else float(self._time[(lo + i) % keep])

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
    duplicates, late_drops, late_crossings`` (``kernel_drops`` ``None`` where not
    counted; callables of the reader and source); ``tracks()`` → confirmed tracks
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
        #: Frames all of whose datagrams came before a restart (plots held in the
        #: checkpoint resumed from, no closing crossing received since): left out.
        self.restored = 0
        self.by_crossing = 0  # frames timed from their closing crossing's datagram
        self.latency_sum = 0.0
        self.latency_count = 0
        #: The last ``window`` latencies: a ring allocated (and written) whole at the
        #: start, so the memory does not grow with the frames.
        self.recent = np.full(int(window), np.nan)
        self.recent_last_plot = np.full(int(window), np.nan)  # the former measure
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
        closing = getattr(out.frame, "closing", None)  # a Scan; a test may pass less
        t_mark = None if closing is None else self.arrivals.time_at(closing)
        if plots.max() < 0:  # every plot held in a checkpoint: came before the restart
            if closing is None:
                self.restored += 1  # timed by the restart, not by the data
                return
            t_plot = None  # earlier than the closing crossing, received since
        else:
            t_plot = self.arrivals.time_of(int(plots.max()))
            if t_plot is None:
                self.untimed += 1
                return
        if closing is not None and t_mark is None:
            self.untimed += 1
            return
        t_in = max(t for t in (t_plot, t_mark) if t is not None)  # the later one known
        self.by_crossing += t_mark is not None and t_mark == t_in
        self._observe(now - t_in, None if t_plot is None else now - t_plot)

    def observe(self, latency_s: float) -> None:
        """One frame's latency (s)."""
        with self._lock:
            self._observe(latency_s)

    def _observe(self, latency_s: float, last_plot_s: float | None = None) -> None:
        self.latency_sum += latency_s
        self.latency_count += 1
        i = self._n_recent % self.recent.size
        self.recent[i] = latency_s
        self.recent_last_plot[i] = latency_s if last_plot_s is None else last_plot_s
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
        and ``count`` of all, ``untimed``, ``after_end``, ``restored`` (frames left out:
        module docstring), ``by_crossing`` (frames timed from their closing crossing)
        and ``last_plot`` (``p50, p99`` of the same frames timed from their last plot's
        datagram, the former measure; a frame of restored plots alone: from its
        crossing) — and ``time`` (the clock)."""
        with self._lock:
            k = min(self._n_recent, self.recent.size)
            p50, p99 = percentiles(self.recent[:k])
            old = percentiles(self.recent_last_plot[:k])
            return {"time": self.clock() if now is None else now, **dict(self.counts()),
                    "frames": self.frames, "tracks": self.n_tracks,
                    "radars_silent": self.silent(),
                    "latency_s": {"p50": p50, "p99": p99, "sum": self.latency_sum,
                                  "count": self.latency_count, "untimed": self.untimed,
                                  "after_end": self.after_end, "restored": self.restored,
                                  "by_crossing": self.by_crossing,
                                  "last_plot": {"p50": old[0], "p99": old[1]}}}

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
        crossings = s.get("late_crossings")  # sector frames: sweep marks too late
        late_crossings = f"{crossings} late crossings, " if crossings else ""
        return (f"live: {rates}{d} datagrams, {p} plots, {s['duplicates']} duplicates, "
                f"{s['late_drops']} late drops, {late_crossings}{s['queue_drops']} queue drops, "
                f"{kernel}, "
                f"{s['frames']} frames, {s['tracks']} tracks, {len(silent)} radars silent"
                f"{' (' + ', '.join(map(str, silent)) + ')' if silent else ''}{lat}")
