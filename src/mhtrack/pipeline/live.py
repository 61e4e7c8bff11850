"""``mhtrack live``: a :class:`~mhtrack.pipeline.Pipeline` over datagrams from the
network or stdin, its tracks out as CAT062 over UDP, rolling CAT062 files and JSON lines,
with a status line every few seconds (``docs/live.md``).

``UdpReader``/``StdinReader`` (:mod:`mhtrack.sources.udp`) → ``DatagramSource`` (decode,
time axis, re-order window, frames) → the tracker → the sinks. A live source has no
survey: the frame lengths come from the sensors file's periods (every radar needs one —
live cannot wait for CAT034 marks before its first frame), and the new-target density
must be given (``TrackOptions.new_target_density``: there are no plots yet to take an
area from). The day of each ASTERIX time of day comes from the datagrams' receive time
(``day_from="receive"``, real feeds: the receive clock must be right to within 12 h) or
from the stream alone (``"stream"``: a recording replayed at another speed or hour).
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO, TextIO

from mhtrack.pipeline.options import TrackOptions
from mhtrack.pipeline.run import Pipeline, RunResult
from mhtrack.sinks.base import CallbackSink, FrameOutput, Sink

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet
    from mhtrack.sources.udp import ReaderStats

DAY_FROM = ("receive", "stream")


@dataclass(frozen=True)
class LiveOptions:
    """Where a live run reads and writes (``None``/empty: not used)."""

    #: ``udp://HOST:PORT`` endpoints to listen on (several LANs: merged).
    listen: tuple[str, ...] = ()
    #: Read stdin instead, with this framing (``raw`` or ``len32``).
    stdin: str | None = None
    #: How the day of a time of day is found (module docstring).
    day_from: str = "receive"
    #: ``udp://HOST:PORT`` destinations of the CAT062 system tracks.
    out_udp: tuple[str, ...] = ()
    #: CAT062 recording (``.ast`` or ``.pcap``), in parts of ``part_frames`` frames.
    out_file: Path | None = None
    part_frames: int | None = None
    #: JSON lines of the online rows on stdout.
    json: bool = False
    #: Seconds between status lines (``None``: none).
    status_every_s: float | None = None
    #: CAT062 data source (I062/010).
    sac: int | None = None
    sic: int | None = None
    reorder_window_s: float | None = None


class Status(CallbackSink):
    """Counts what the run did; :meth:`line` is the status line since the last call:
    ``datagrams/s, plots/s, frames, late drops, queue drops, tracks`` (tracks: reported
    at the last frame)."""

    def __init__(self, reader: ReaderStats, source_stats: Callable[[], Any]) -> None:
        super().__init__(self._count)
        self.reader, self.source_stats = reader, source_stats
        self.frames = self.tracks = 0
        self._last: tuple[float, int, int] | None = None

    def _count(self, out: FrameOutput) -> None:
        self.frames += 1
        self.tracks = len(out.online)

    def line(self, now: float) -> str:
        """The status line at time ``now`` (s); rates over the time since the last line
        (since the first call: totals only)."""
        s = self.source_stats()
        d, p = self.reader.datagrams, s.plots_in
        rates = ""
        if self._last is not None and now > self._last[0]:
            dt = now - self._last[0]
            rates = (f"{(d - self._last[1]) / dt:.1f} datagrams/s, "
                     f"{(p - self._last[2]) / dt:.1f} plots/s, ")
        self._last = (now, d, p)
        return (f"live: {rates}{d} datagrams, {p} plots, {self.frames} frames, "
                f"{s.late_dropped} late drops, {self.reader.queue_dropped} queue drops, "
                f"{self.tracks} tracks")


@dataclass(frozen=True)
class LiveResult:
    """What a live run did."""

    run: RunResult
    reader: ReaderStats
    #: CAT062 datagrams and rows sent over UDP (all destinations).
    sent_datagrams: int
    sent_rows: int
    files: tuple[Path, ...]

    def describe(self) -> str:
        """One line: datagrams received, the run, CAT062 sent, files."""
        files = f", {len(self.files)} CAT062 files" if self.files else ""
        return (f"received {self.reader.datagrams} datagrams "
                f"({self.reader.queue_dropped} dropped in the queue); {self.run.describe()}; "
                f"sent {self.sent_datagrams} CAT062 datagrams ({self.sent_rows} rows){files}")


class Live:
    """The assembled live run (module docstring); :meth:`run` until ``stop`` is set or
    the input ends. ``stdin``/``stdout``: the streams of ``LiveOptions.stdin`` and
    ``json``; ``emit``: where status lines go."""

    def __init__(self, sensors: SensorSet, options: TrackOptions, live: LiveOptions, *,
                 stop: threading.Event | None = None, stdin: BinaryIO | None = None,
                 stdout: TextIO | None = None,
                 emit: Callable[[str], None] | None = None) -> None:
        from mhtrack.sinks.files import Cat062Sink
        from mhtrack.sinks.stream import Cat062UdpSink, JsonLinesSink
        from mhtrack.sources.datagrams import DatagramSource
        from mhtrack.sources.udp import StdinReader, UdpReader

        if options.new_target_density is None:
            raise ValueError("live: give the new-target density (--birth-density): a live "
                             "feed has no plots yet to take the surveillance area from")
        no_period = [s.id for s in sensors.sensors if s.period is None]
        if no_period:
            raise ValueError(f"live: the sensors file gives no period for radar(s) "
                             f"{', '.join(map(str, no_period))}: live frames need each "
                             "radar's rotation period (it cannot survey CAT034 first)")
        if live.day_from not in DAY_FROM:
            raise ValueError(f"unknown day_from {live.day_from!r} (expected "
                             f"{', '.join(DAY_FROM)})")
        if (live.stdin is None) == (not live.listen):
            raise ValueError("live: listen on UDP endpoints or read stdin (one of them)")
        self.live, self.emit = live, emit
        self.stop = threading.Event() if stop is None else stop
        if live.stdin is not None:
            self.reader: UdpReader | StdinReader = StdinReader(
                stdin if stdin is not None else sys.stdin.buffer, framing=live.stdin,
                stop=self.stop)
            name = "stdin"
        else:
            self.reader = UdpReader(list(live.listen), stop=self.stop)
            name = ",".join(self.reader.names)
        datagrams: Iterable[Any] = self.reader
        if live.day_from == "stream":
            datagrams = (d for d, _ in self.reader)
        self.source = DatagramSource(datagrams, sensors=sensors, name=name,
                                     reorder_window_s=live.reorder_window_s,
                                     chunk=1)  # each data block on as it arrives
        try:
            self.pipeline = Pipeline(self.source, options)
        except BaseException:
            if isinstance(self.reader, UdpReader):
                self.reader.close()
            raise
        frame = self.pipeline.frame
        if frame is None and (live.out_udp or live.out_file is not None):
            raise ValueError("live: CAT062 output needs the sensors' geodetic reference")
        self.udp = [Cat062UdpSink(to, frame, sac=live.sac, sic=live.sic)  # type: ignore[arg-type]
                    for to in live.out_udp]
        self.files = None if live.out_file is None else Cat062Sink(
            live.out_file, frame, output="online", sac=live.sac,  # type: ignore[arg-type]
            sic=live.sic, part_frames=live.part_frames, empty_ok=True)
        self.status = Status(self.reader.stats, lambda: self.source.stats)
        self.sinks: list[Sink] = [*self.udp, self.status]
        if self.files is not None:
            self.sinks.append(self.files)
        if live.json:
            self.sinks.append(JsonLinesSink(stdout if stdout is not None else sys.stdout,
                                            frame))

    @property
    def listening(self) -> list[str]:
        """The endpoints bound (``udp://HOST:PORT``), or ``["stdin"]``."""
        return list(getattr(self.reader, "names", ["stdin"]))

    def _report(self, done: threading.Event) -> None:
        every = self.live.status_every_s
        assert every is not None and self.emit is not None
        self.status.line(time.monotonic())
        while not done.wait(every):
            self.emit(self.status.line(time.monotonic()))

    def run(self) -> LiveResult:
        """Track until the input ends or :attr:`stop` is set; every sink is closed."""
        done = threading.Event()
        reporter = None
        if self.live.status_every_s and self.emit is not None:
            reporter = threading.Thread(target=self._report, args=(done,), daemon=True,
                                        name="mhtrack-status")
            reporter.start()
        try:
            result = self.pipeline.run(self.sinks)
        finally:
            done.set()
            self.stop.set()
            if reporter is not None:
                reporter.join()
        files = tuple(self.files.paths) if self.files is not None else ()
        return LiveResult(result, self.reader.stats, sum(s.datagrams for s in self.udp),
                          sum(s.rows for s in self.udp), files)
