"""``mhtrack live``: a :class:`~mhtrack.pipeline.Pipeline` over datagrams from the
network or stdin, its tracks out as CAT062 over UDP, rolling CAT062 files and JSON lines
— on update or on a fixed period of data time (:mod:`mhtrack.sinks.periodic`) —, its
health and latency every few seconds (:mod:`~mhtrack.pipeline.health`: a status line, a
JSON file, Prometheus text) and checkpoints of the tracker to restart from
(:mod:`~mhtrack.pipeline.checkpoint`) (``docs/live.md``).

``UdpReader``/``StdinReader`` (:mod:`mhtrack.sources.udp`) → ``DatagramSource`` (decode,
time axis, re-order window, frames) → the tracker → the sinks. A live source has no
survey of the whole input: the frame lengths come from the sensors file's periods and
the new-target density from ``TrackOptions.new_target_density``; what is not given is
taken from the first rotations (:mod:`~mhtrack.pipeline.warmup`). The day of each
ASTERIX time of day comes from the datagrams' receive time
(``day_from="receive"``, real feeds: the receive clock must be right to within 12 h) or
from the stream alone (``"stream"``: a recording replayed at another speed or hour).
"""

from __future__ import annotations

import itertools
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO, TextIO

import numpy as np

from mhtrack.pipeline.checkpoint import (
    CheckpointSink,
    LiveState,
    decode_pending,
    encode_pending,
    read_checkpoint,
)
from mhtrack.pipeline.health import LATE, Health
from mhtrack.pipeline.live_options import (
    DAY_FROM,
    DEFAULT_STATUS_EVERY_S,
    EXTRAPOLATION_PERIODS,
    KEEP_ROWS,
    LiveOptions,
    idle_wait,
    longest_period,
)
from mhtrack.pipeline.monitor import MetricsServer, host_port, prometheus_text, write_status
from mhtrack.pipeline.options import TrackOptions
from mhtrack.pipeline.registration_state import encode_state
from mhtrack.pipeline.run import Pipeline, RunResult
from mhtrack.pipeline.view import ViewServer, ViewSink, radar_list
from mhtrack.pipeline.warmup import Warmup, warm_up
from mhtrack.sinks.base import FrameOutput, Sink
from mhtrack.sources.base import CAUGHT_UP, IDLE

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet
    from mhtrack.records import TrackTable
    from mhtrack.sources.base import Survey
    from mhtrack.sources.udp import ReaderStats


@dataclass(frozen=True)
class LiveResult:
    """What a live run did."""

    run: RunResult
    reader: ReaderStats
    #: CAT062 datagrams and rows sent over UDP (all destinations).
    sent_datagrams: int
    sent_rows: int
    files: tuple[Path, ...]
    #: The final health snapshot (:meth:`Health.snapshot`).
    health: dict[str, Any]
    #: Ticks of the period output sent, checkpoints written.
    ticks: int = 0
    checkpoints: int = 0

    def describe(self) -> str:
        """One line: datagrams received, late drops and crossings (when any), the run,
        CAT062 sent, files, latency."""
        files = f", {len(self.files)} CAT062 files" if self.files else ""
        h, lat = self.health, self.health["latency_s"]  # late: as the status line, when any
        late = "".join(f", {h[k]} {k.replace('_', ' ')}" for k in LATE if h.get(k))
        extra = (f"; {self.ticks} ticks" if self.ticks else "") + \
            (f"; {self.checkpoints} checkpoints" if self.checkpoints else "")
        latency = ("" if not lat["count"] else
                   f"; latency p50 {1e3 * lat['p50']:.0f} ms, p99 {1e3 * lat['p99']:.0f} ms "
                   f"({lat['count']} frames)")
        return (f"received {self.reader.datagrams} datagrams "
                f"({self.reader.queue_dropped} dropped in the queue){late}; {self.run.describe()}; "
                f"sent {self.sent_datagrams} CAT062 datagrams ({self.sent_rows} rows){files}"
                f"{extra}{latency}")


class Live:
    """The assembled live run (module docstring); :meth:`run` until ``stop`` is set or
    the input ends. ``stdin``/``stdout``: the streams of ``LiveOptions.stdin`` and
    ``json``; ``emit``: where status lines go; ``clock``: the receive times' clock;
    ``idle_clock``: the clock of ``LiveOptions.idle_close_s`` (tests pass their own)."""

    def __init__(self, sensors: SensorSet, options: TrackOptions, live: LiveOptions, *,
                 stop: threading.Event | None = None, stdin: BinaryIO | None = None,
                 stdout: TextIO | None = None, emit: Callable[[str], None] | None = None,
                 clock: Callable[[], float] = time.time,
                 idle_clock: Callable[[], float] = time.monotonic) -> None:
        from mhtrack.io.asterix.timeaxis import TimeAxis
        from mhtrack.sources.datagrams import DatagramSource
        from mhtrack.sources.udp import StdinReader, UdpReader

        if live.day_from not in DAY_FROM:
            raise ValueError(f"unknown day_from {live.day_from!r} (expected "
                             f"{', '.join(DAY_FROM)})")
        if (live.stdin is None) == (not live.listen):
            raise ValueError("live: listen on UDP endpoints or read stdin (one of them)")
        if live.resume and live.checkpoint is None:
            raise ValueError("live: --resume needs --checkpoint FILE")
        self.live, self.emit = live, emit
        if live.preload:  # before "listening on": senders wait for that line
            from mhtrack.pipeline.preload import preload
            preload()
        self.stop = threading.Event() if stop is None else stop
        resumed = None
        if live.resume and live.checkpoint is not None and live.checkpoint.exists():
            resumed = read_checkpoint(live.checkpoint, options, live.sectors)
        #: The checkpoint resumed from (``None``: a fresh start).
        self.resumed: LiveState | None = None if resumed is None else resumed[1]
        #: The density comes from the first rotations (not given, not resumed).
        self.live_density_needed = options.new_target_density is None and resumed is None
        if live.stdin is not None:
            self.reader: UdpReader | StdinReader = StdinReader(
                stdin if stdin is not None else sys.stdin.buffer, framing=live.stdin,
                stop=self.stop, clock=idle_clock)
            name = "stdin"
        else:
            self.reader = UdpReader(list(live.listen), stop=self.stop, clock=idle_clock)
            name = ",".join(self.reader.names)
        if emit is not None:  # before any warm-up: a sender may wait for this line
            if self.resumed is not None:
                emit(f"resumed from {live.checkpoint} (frame {self.resumed.next_frame}, "
                     f"time {self.resumed.last_time} s)")
            emit(f"listening on {', '.join(self.listening)}")
        incoming: Iterator[tuple[bytes, float]] = iter(self.reader)
        survey = None
        #: The first rotations surveyed (:mod:`~mhtrack.pipeline.warmup`), if needed.
        self.warmup: Warmup | None = None
        if self.live_density_needed or any(
                s.period is None for s in sensors.sensors if s.kind == "polar"):
            sensors, survey, incoming = self._warm_up(sensors, incoming, name)
        # a quiet feed closes the frames held after a bounded wall-clock wait
        self.reader.idle_s = idle_wait(sensors, live)
        axis = None
        st = self.resumed
        if st is not None:
            axis = TimeAxis()
            axis.day0, axis.latest = st.axis_day0, st.axis_latest
        self.health = Health(self._counts, self._tracks, self._plot_numbers,
                             {s.id: float(s.period) for s in sensors.sensors  # type: ignore[arg-type]
                              if s.kind == "polar" and s.period is not None}, clock)
        self.source = DatagramSource(
            self._arrived(incoming), sensors=sensors, name=name,
            reorder_window_s=live.reorder_window_s,  # what has queued up: one chunk
            axis=axis, first_frame=0 if st is None else st.next_frame,
            first_row=0 if st is None else st.next_row,
            not_before=None if st is None else st.last_time,
            pending=None if st is None else decode_pending(st.pending),
            recent=None if st is None else st.duplicates,
            keep_rows=KEEP_ROWS,  # the health looks up the frame just made
            release=live.release, sectors=live.sectors,
            # stopped with a checkpoint: the plots held go into it, tracked on resume
            hold=lambda: self.stop.is_set() and live.checkpoint is not None)
        try:
            self.pipeline = Pipeline(self.source, options, survey=survey, live=True)
        except BaseException:
            if isinstance(self.reader, UdpReader):
                self.reader.close()
            raise
        if resumed is not None:  # the same track ids, hypotheses and clutter go on
            self.pipeline.tracker = resumed[0]
            self.pipeline.config = resumed[0].config
            self._resume_bias(resumed[1])
        elif survey is not None and self.emit is not None:
            note = self.pipeline.birth_note
            if note is not None:
                span = 0.0 if self.warmup is None else self.warmup.span_s
                self.emit(f"live, from the first {span:.0f} s: {note}")
        self._make_sinks(sensors, stdout)

    def _resume_bias(self, state: LiveState) -> None:
        """The bias estimate of the checkpoint (with ``--estimate-bias``), checked."""
        from mhtrack.errors import InputError
        from mhtrack.pipeline.registration_state import restore_state

        reg = self.pipeline.registration
        if reg is None or state.bias is None:
            return
        try:
            restore_state(reg, state.bias)
        except ValueError as e:
            path = self.live.checkpoint
            raise InputError(f"{path}: member 'meta': field 'extra.bias': {e}",
                             file=str(path)) from None

    def _warm_up(self, sensors: SensorSet, incoming: Iterator[tuple[bytes, float]],
                 name: str) -> tuple[SensorSet, Survey | None, Iterator[Any]]:
        """The first rotations surveyed (:mod:`~mhtrack.pipeline.warmup`): the sensors
        with their periods, the survey the defaults come from as ``track``'s survey of a
        recording (``None``: the density was given) and the datagrams, those held
        first."""
        from mhtrack.io.asterix.api import sensors_with_periods

        self.warmup = warm = warm_up(incoming, sensors, name=name,
                       use_receive_time=self.live.day_from == "receive",
                       reorder_window_s=self.live.reorder_window_s, stop=self.stop)
        sensors = sensors_with_periods(sensors, warm.periods)
        missing = [s.id for s in sensors.sensors if s.kind == "polar" and s.period is None]
        if missing and not self.stop.is_set():
            raise ValueError(
                f"live: no rotation period for radar(s) {', '.join(map(str, missing))} in "
                f"the sensors file nor from their CAT034 marks in the first "
                f"{warm.span_s:.0f} s: give period in the sensors file")
        if self.emit is not None and warm.periods:
            self.emit("live: periods " + ", ".join(
                f"radar {k} {v:.3g} s" for k, v in sorted(warm.periods.items())))
        survey = warm.survey if self.live_density_needed else None
        return sensors, survey, itertools.chain(warm.datagrams, incoming)

    def _make_sinks(self, sensors: SensorSet, stdout: TextIO | None) -> None:
        from mhtrack.sinks.files import Cat062Sink
        from mhtrack.sinks.periodic import PeriodicSink
        from mhtrack.sinks.stream import Cat062UdpSink, JsonLinesSink

        live, frame = self.live, self.pipeline.frame
        if frame is None and (live.out_udp or live.out_file is not None):
            raise ValueError("live: CAT062 output needs the sensors' geodetic reference")
        if frame is None and live.view is not None:
            raise ValueError("live: the view needs the sensors' geodetic reference")
        self.udp = [Cat062UdpSink(to, frame, sac=live.sac, sic=live.sic)  # type: ignore[arg-type]
                    for to in live.out_udp]
        self.files = None if live.out_file is None else Cat062Sink(
            live.out_file, frame, output="online", sac=live.sac,  # type: ignore[arg-type]
            sic=live.sic, part_frames=live.part_frames, empty_ok=True)
        outputs: list[Sink] = [*self.udp]
        if self.files is not None:
            outputs.append(self.files)
        if live.json:
            outputs.append(JsonLinesSink(stdout if stdout is not None else sys.stdout, frame,
                                         label="frame" if live.period_out_s is None
                                         else "tick"))
        self.periodic: PeriodicSink | None = None
        if live.period_out_s is not None:
            longest = longest_period(sensors)
            longest = live.period_out_s if longest is None else longest
            self.periodic = PeriodicSink(
                outputs, live.period_out_s, self._picture,
                max_extrapolation_s=(EXTRAPOLATION_PERIODS * longest
                                     if live.max_extrapolation_s is None
                                     else live.max_extrapolation_s),
                next_tick=None if self.resumed is None else self.resumed.next_tick)
            if self.resumed is not None and self.pipeline.tracker.last_time is not None:
                self.periodic.resume(self._picture(None), self.pipeline.tracker.last_time)
            outputs = [self.periodic]
        self.checkpoints = None if live.checkpoint is None else CheckpointSink(
            live.checkpoint, lambda: self.pipeline.tracker, self._state,
            live.checkpoint_every_s, self.pipeline.options, live.sectors)
        #: The live view's tracks (``--view``), or ``None``.
        self.view: ViewSink | None = None if live.view is None else ViewSink(
            lambda: self.pipeline.tracker, frame)  # type: ignore[arg-type]
        self._radars = radar_list(sensors)
        # the health sink comes after the outputs (its time is the frame's out time)
        self.sinks: list[Sink] = [*outputs, self.health]
        if self.view is not None:
            self.sinks.append(self.view)
        if self.checkpoints is not None:
            self.sinks.append(self.checkpoints)

    # -- what the health, period output and checkpoints read --------------------------
    def _arrived(self, reader: Iterable[tuple[bytes, float]]) -> Iterator[Any]:
        """The reader's datagrams, each receive time noted for the latency first, and
        :data:`~mhtrack.sources.base.CAUGHT_UP` after one when no other is waiting (the
        source decodes what has queued up as one chunk, and passes it on then)."""
        stream = self.live.day_from == "stream"
        waiting = self.reader.waiting
        for item in reader:
            if item is IDLE:
                yield item
                continue
            data, when = item
            self.health.arrivals.add(self.source.decoded, when, len(data))
            yield data if stream else (data, when)
            if not waiting():
                yield CAUGHT_UP
        self.health.input_ended = True

    def _counts(self) -> dict[str, int | None]:
        s, r = self.source.stats, self.reader.stats
        return {"datagrams": r.datagrams, "queue_drops": r.queue_dropped,
                "kernel_drops": r.kernel_dropped, "plots": s.plots_in,
                "duplicates": self.source.problems.counts.get("duplicate", 0),
                "late_drops": s.late_dropped, "late_crossings": s.late_crossings,
                "idle_closes": self.source.idles}

    def _tracks(self) -> int:
        return int(np.count_nonzero(self.pipeline.tracker.leaves.reported()))

    def _plot_numbers(self, out: FrameOutput) -> np.ndarray:
        return self.source.file_rows(out.frame.rows)

    def _picture(self, out: FrameOutput | None) -> TrackTable:
        """Every confirmed track of the tracker now, at its own time."""
        from mhtrack.mht.report import report
        from mhtrack.sinks.periodic import empty_frame

        trk = self.pipeline.tracker
        scan = empty_frame(-1, trk.last_time or 0.0) if out is None else out.frame
        return report(scan, trk.leaves)

    def view_state(self) -> dict[str, Any]:
        """What ``/view.json`` serves: the view's tracks (:meth:`ViewSink.picture`), the
        radars (:func:`~mhtrack.pipeline.view.radar_list`) and ``status``, the health
        snapshot (as ``--status-json``)."""
        picture = {"frame": None, "time": None, "tracks": []} if self.view is None \
            else self.view.picture()
        return {**picture, "radars": self._radars, "status": self.health.snapshot()}

    def _state(self) -> LiveState:
        axis = self.source.axis
        return LiveState(self.source.next_frame, axis.day0, axis.latest,
                         self.pipeline.tracker.last_time,
                         None if self.periodic is None else self.periodic.next_tick,
                         encode_pending(self.source.pending()), self.source.next_row,
                         self.source.recent_blocks() or None,
                         None if self.pipeline.registration is None
                         else encode_state(self.pipeline.registration))

    # -- running ----------------------------------------------------------------------
    @property
    def listening(self) -> list[str]:
        """The endpoints bound (``udp://HOST:PORT``), or ``["stdin"]``."""
        return list(getattr(self.reader, "names", ["stdin"]))

    def _publish(self, server: MetricsServer | None, line: bool) -> None:
        snap = self.health.snapshot()
        if line and self.emit is not None:
            self.emit(self.health.line(snap))
        write_status(snap, self.live.status_json, self.live.prometheus)
        if server is not None:
            server.update(prometheus_text(snap))

    def _report(self, done: threading.Event, server: MetricsServer | None) -> None:
        live = self.live
        every = live.status_every_s or DEFAULT_STATUS_EVERY_S
        self.health.line(self.health.snapshot())  # the rates start here
        while not done.wait(every):
            self._publish(server, live.status_every_s is not None)

    def run(self) -> LiveResult:
        """Track until the input ends or :attr:`stop` is set; every sink is closed (a
        final checkpoint and status written)."""
        live = self.live
        server = None
        if live.metrics_http is not None:
            server = MetricsServer(*host_port(live.metrics_http, "metrics endpoint"))
            #: The metrics endpoint's bound ``host, port``.
            self.metrics_address = server.address
            if self.emit is not None:
                self.emit(f"metrics on http://{server.address[0]}:{server.address[1]}"
                          "/metrics")
        view = None
        if live.view is not None:
            view = ViewServer(*host_port(live.view, "view"), self.view_state)
            #: The view's bound ``host, port`` and its page's URL.
            self.view_address, self.view_url = view.address, view.url
            if self.emit is not None:
                self.emit(f"view on {view.url}")
        done = threading.Event()
        reporter = None
        if (live.status_every_s and self.emit is not None) or live.status_json or \
                live.prometheus or server is not None:
            reporter = threading.Thread(target=self._report, args=(done, server),
                                        daemon=True, name="mhtrack-status")
            reporter.start()
        try:
            result = self.pipeline.run(self.sinks, keep_stats=False)
        finally:
            done.set()
            self.stop.set()
            if reporter is not None:
                reporter.join()
            if view is not None:
                view.close()
        self._publish(server, False)  # the final figures
        if server is not None:
            server.close()
        files = tuple(self.files.paths) if self.files is not None else ()
        return LiveResult(result, self.reader.stats, sum(s.datagrams for s in self.udp),
                          sum(s.rows for s in self.udp), files, self.health.snapshot(),
                          0 if self.periodic is None else self.periodic.ticks,
                          0 if self.checkpoints is None else self.checkpoints.written)
