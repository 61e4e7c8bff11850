"""The tracker stepped frame by frame from a source into sinks (:class:`Pipeline`).

Fusion (``fusion``): the MHT assumes at most one plot per target per scan, so with
several sensors each scan is first fused by
:class:`~mhtrack.initiation.AdaptiveKMeansFusion` (P2 §1.2) with a χ² consistency split
and information weighting (:func:`~mhtrack.build.tracker_fuser`). A fused plot's row id
(the ``plot`` column of the tracks) is the row of the first plot of its cluster (in scan
order), so it stays a row of the source.
"""

from __future__ import annotations

import dataclasses
import logging
from collections import deque
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.build import TRACKER_FUSERS, takes_clutter_density, tracker_fuser
from mhtrack.names import TRACKER_FUSIONS
from mhtrack.pipeline.frame_log import log_frame
from mhtrack.pipeline.options import TrackOptions, birth_density_note, choose
from mhtrack.progress import Count
from mhtrack.records import Scan
from mhtrack.sinks.base import FrameOutput, Sink

if TYPE_CHECKING:
    from mhtrack.initiation.fusion import AdaptiveKMeansFusion
    from mhtrack.mht import MHTConfig, MHTTracker, StepStats
    from mhtrack.pipeline.registration import Registration
    from mhtrack.sources.base import Source, Survey

#: The per-frame DEBUG lines (``mhtrack -vv``).
_log = logging.getLogger("mhtrack.pipeline")


def fuse_scan(scan: Scan, fuser: AdaptiveKMeansFusion | None = None) -> Scan:
    """``scan`` fused by adaptive K-means (P2 §1.2): one plot per cluster, with its fused
    ``R`` and, as row id, the row of the cluster's first plot (module docstring). Default
    ``fuser``: :func:`~mhtrack.build.tracker_fuser`."""
    if len(scan) == 0:
        return scan
    f = (tracker_fuser() if fuser is None else fuser).fuse(scan)
    k = len(f.scan)
    first = np.full(k, -1, np.int64)
    first[f.labels[::-1]] = np.arange(len(f.labels))[::-1]
    return dataclasses.replace(f.scan, rows=np.asarray(scan.rows, np.int64)[first])


def fused(scans: Iterable[Scan], fusion: str,
          caps: dict[int, dict[str, int]] | None = None) -> Iterable[Scan]:
    """``scans`` unchanged (``"none"``) or each fused (``"adaptive-kmeans"``). The caps
    the fusion applied in a burst (``Fuser.caps_``, logged by ``Fuser.fuse``) go to
    ``caps[scan index]``."""
    if fusion not in TRACKER_FUSIONS:
        raise ValueError(f"unknown fusion {fusion!r} (expected {', '.join(TRACKER_FUSIONS)})")
    factory = TRACKER_FUSERS[fusion]
    if factory is None:
        return scans
    fuser = factory()

    def each(s: Scan) -> Scan:
        out = fuse_scan(s, fuser)  # logs the caps that acted (Fuser.fuse)
        acted = dict(getattr(fuser, "caps_", None) or {}) if len(s) else {}
        if acted and caps is not None:
            caps[int(s.index)] = acted
        return out

    return (each(s) for s in scans)


def step_frames(tracker: MHTTracker, frames: Iterable[Scan], *, fusion: str = "none",
                name: str = "mht", progress: bool = False,
                total: int | None = None, unit: str = "frame",
                registration: Registration | None = None) -> Iterator[FrameOutput]:
    """Each frame fused (``fusion``), stepped through ``tracker``, and its output — the
    online rows, the backfill and the step's statistics with the fusion's caps merged
    in. ``progress``: a bar (:class:`~mhtrack.progress.Count`) of ``total`` frames, or
    of ``total`` plots with ``unit="plot"`` (timed plots and recordings, whose number of
    frames is known only at the end); at DEBUG, one line per frame
    (:func:`~mhtrack.pipeline.frame_log.log_frame`). ``registration``: each frame's
    plots corrected for the radars' biases before fusion, and the estimate updated
    from the step's confirmed tracks (:mod:`mhtrack.pipeline.registration`)."""
    fusion_caps: dict[int, dict[str, int]] = {}
    depth = getattr(getattr(tracker, "config", None), "history_scans", None)
    recent: deque[int] = deque(maxlen=max(int(depth or 0), 1))
    if registration is not None:
        frames = (registration.correct(f) for f in frames)
    with Count(total, name, unit, progress) as bar:
        for scan in fused(frames, fusion, fusion_caps):
            online = tracker.step(scan)
            if registration is not None:
                registration.learn(scan, online)
            stats = tracker.last_stats
            assert stats is not None  # set by every step
            stats.caps.update(fusion_caps.pop(stats.scan, {}))
            if _log.isEnabledFor(logging.DEBUG):
                log_frame(_log, scan, tracker, stats)
            # the next backfill reaches back to the oldest of the last ``depth`` frames
            recent.append(int(scan.index))
            bar.update(len(scan) if unit == "plot" else 1)
            yield FrameOutput(scan, online, tracker.last_backfill, stats,
                              None if depth is None else recent[0])


def mean_step_time(stats: Sequence[StepStats]) -> float:
    """Mean tracker time per scan (s) — P1 Table 3's ``Tavg``."""
    t = np.array([s.time_s for s in stats])
    return float(t.mean()) if t.size else 0.0


def caps_acted(stats: Sequence[StepStats]) -> dict[str, int]:
    """Total of every hard cap that acted over ``stats``, and under ``"scans"`` the number
    of scans (frames) on which any acted; empty when none acted."""
    total: dict[str, int] = {}
    for s in stats:
        for k, v in s.caps.items():
            total[k] = total.get(k, 0) + v
    if total:
        total["scans"] = sum(1 for s in stats if s.caps)
    return total


def cap_scans(stats: Sequence[StepStats]) -> dict[str, list[int]]:
    """The scans at which each hard cap acted (``StepStats.caps``; with the fusion's
    caps, ``fusion_*``, of each scan)."""
    out: dict[str, list[int]] = {}
    for s in stats:
        for k in sorted(s.caps):
            out.setdefault(k, []).append(s.scan)
    return out


class StatsSummary:
    """What the run printout needs of the steps' statistics, summed step by step (the
    number of steps, their total time, :func:`caps_acted`) without keeping them."""

    def __init__(self) -> None:
        self.n = 0
        self.time_s = 0.0
        self.caps: dict[str, int] = {}
        self.cap_steps = 0

    def add(self, s: StepStats) -> None:
        """One more step."""
        self.n += 1
        self.time_s += s.time_s
        for k, v in s.caps.items():
            self.caps[k] = self.caps.get(k, 0) + v
        self.cap_steps += bool(s.caps)

    def caps_acted(self) -> dict[str, int]:
        """As :func:`caps_acted` of the steps added."""
        return {**self.caps, "scans": self.cap_steps} if self.caps else {}


@dataclass(frozen=True)
class RunResult:
    """What a pipeline run did (the tracks went to the sinks)."""

    tracker: str
    #: Every step's statistics (empty when the run was asked not to keep them).
    stats: tuple[StepStats, ...]
    #: Distinct track ids reported.
    n_tracks: int
    #: Frames of timed plots (True) or synchronous scans.
    timed: bool = False
    #: The steps summed (:class:`StatsSummary`); by default that of ``stats``.
    summary: StatsSummary | None = None

    def _summary(self) -> StatsSummary:
        if self.summary is not None:
            return self.summary
        s = StatsSummary()
        for x in self.stats:
            s.add(x)
        return s

    @property
    def t_avg(self) -> float:
        """Mean tracker time per scan (s)."""
        if self.summary is None:
            return mean_step_time(self.stats)
        return self.summary.time_s / self.summary.n if self.summary.n else 0.0

    @property
    def caps(self) -> dict[str, int]:
        """:func:`caps_acted` of the run."""
        return caps_acted(self.stats) if self.summary is None else self.summary.caps_acted()

    def describe(self) -> str:
        """``TRACKER: N scans|frames, M tracks, T ms/scan[, caps acted: …]``."""
        caps = f", caps acted: {self.caps}" if self.caps else ""
        steps = "frames" if self.timed else "scans"
        return (f"{self.tracker}: {self._summary().n} {steps}, {self.n_tracks} tracks, "
                f"{1e3 * self.t_avg:.2f} ms/scan{caps}")


class Pipeline:
    """A source, the tracker built for it, and the run into sinks.

    Every default is chosen once, here (:func:`~mhtrack.pipeline.options.choose`):
    configuration (``config`` if given, else from the source's scenario or plots),
    fusion, the tracker with the source's sensors, the output frame. ``options``: what
    the user set (:class:`TrackOptions`); ``survey``: the source's survey when it was
    taken elsewhere (else :meth:`Source.survey`); ``live``: a live run (its default
    output mode is online)."""

    def __init__(self, source: Source, options: TrackOptions | None = None, *,
                 config: MHTConfig | None = None, survey: Survey | None = None,
                 live: bool = False) -> None:
        self.source = source
        self.options = TrackOptions() if options is None else options
        if survey is not None:  # surveyed elsewhere (live: its first rotations)
            self.__dict__["survey"] = survey
        survey = self.survey if source.scenario is None else None
        self.choices = choose(source, self.options, survey, config, live=live)
        self.config, self.tracker = self.choices.config, self.choices.tracker
        self.fusion, self.frame = self.choices.fusion, self.choices.frame
        self.output = self.choices.output
        self.registration = self._registration()

    def _registration(self) -> Registration | None:
        """The bias estimation asked for (``TrackOptions.estimate_bias``), or None."""
        o = self.options
        if not o.estimate_bias:
            return None
        from mhtrack.pipeline.registration import Registration

        if self.source.sensors is None or self.source.sensors.reference is None:
            raise ValueError("--estimate-bias needs the radars' sites (a sensors file or "
                             "a recording's CAT034 sites)")
        return Registration(self.source.sensors, reference=o.bias_reference,
                            prior=o.bias_prior)

    @classmethod
    def open(cls, path: str | Path, options: TrackOptions | None = None, *,
             scenario_file: str | None = None, sensors_file: str | None = None,
             reorder_window_s: float | None = None, progress: bool = False,
             sectors: bool = False) -> Pipeline:
        """A pipeline on a plots file or a recording (:func:`~mhtrack.pipeline.open_input`;
        ``sectors``: a recording's frames at its radars' own sectors); ``progress``: a
        bar over the source's survey (:attr:`Source.progress`)."""
        from mhtrack.pipeline.inputs import open_input

        source = open_input(path, scenario_file=scenario_file, sensors_file=sensors_file,
                            reorder_window_s=reorder_window_s, sectors=sectors)
        source.progress = progress
        return cls(source, options)

    @cached_property
    def survey(self) -> Survey | None:
        """The source's survey, read once."""
        return self.source.survey()

    @property
    def birth_note(self) -> str | None:
        """The line naming the new-target density chosen — for rotating radars, with the
        clutter density and the deletion, radar by radar
        (:meth:`~mhtrack.build.RadarRule.note`) — (None when the user set both)."""
        radars, given = self.choices.radars, self.options.new_target_density is not None
        known = (takes_clutter_density(self.options.tracker)
                 and self.options.clutter_density is None)
        if radars is not None:
            if given and not known:
                return None
            return radars.note(self.config.alpha, self.config.beta, birth=not given,
                               known=known)
        if given:
            return None
        return birth_density_note(self.config.new_target_density, self.choices.area_text)

    @property
    def reach_note(self) -> str | None:
        """The line giving each radar's reach learned from its plots (radars without
        ``max_range`` in the sensors file: :mod:`mhtrack.mht.reach`), min / median / max
        over its sectors; ``None`` when no radar needed it."""
        reach = getattr(self.tracker.coverage, "reach", None)
        learned = {} if reach is None else reach.summary()
        if not learned:
            return None
        parts = ", ".join(f"radar {sid} {lo / 1e3:.0f}/{med / 1e3:.0f}/{hi / 1e3:.0f} km"
                          for sid, (lo, med, hi) in sorted(learned.items()))
        return (f"reach learned from the plots (no max_range in the sensors file; min/"
                f"median/max over {reach.sectors} sectors): {parts}")

    @property
    def output_note(self) -> str | None:
        """The line saying the history is smoothed when that was chosen by default
        (timed plots of rotating radars), else ``None``."""
        if self.options.output is not None or self.output != "smoothed":
            return None
        return ("output: the history with each track smoothed over its rows (fixed-interval "
                "Rauch-Tung-Striebel, IMM-aware); --output history for the filtered rows, "
                "online for the rows as reported")

    def outputs(self, *, progress: bool = False) -> Iterator[FrameOutput]:
        """The tracker's output frame by frame (the iterator form of a sink)."""
        survey = self.survey if progress else None
        frames = None if survey is None else survey.n_frames
        plots = None if survey is None or frames is not None else survey.n_plots
        yield from step_frames(self.tracker, self.source, fusion=self.fusion,
                               name=self.options.tracker, progress=progress,
                               total=frames if plots is None else plots,
                               unit="frame" if plots is None else "plot",
                               registration=self.registration)

    def run(self, sinks: Sequence[Sink] = (), *, progress: bool = False,
            keep_stats: bool = True) -> RunResult:
        """Step the tracker over every frame of the source into ``sinks`` (each
        started before the first frame and closed after the last). ``keep_stats``:
        keep every step's :class:`StepStats` in :attr:`RunResult.stats` (else only their
        :class:`StatsSummary`: memory flat in the run's length). With the output
        ``smoothed`` the sinks that keep rows (:attr:`Sink.keeps_rows`) get the history
        smoothed (:class:`~mhtrack.sinks.smoothed.SmoothedHistory`), the others each
        frame's output as the tracker reported it."""
        summary = StatsSummary()
        if self.output == "smoothed":  # tables get the history smoothed (sinks/smoothed.py)
            from mhtrack.sinks.smoothed import SmoothedHistory

            self.tracker.keep_models = True
            tables = [s for s in sinks if s.keeps_rows]
            sinks = [SmoothedHistory(tables, self.tracker.motion),
                     *(s for s in sinks if not s.keeps_rows)]
        stats, n_tracks = feed(self.outputs(progress=progress), sinks, self.source,
                               backfill_ids=self.output != "online", summary=summary,
                               keep_stats=keep_stats)
        return RunResult(self.options.tracker, tuple(stats), n_tracks, self.source.timed,
                         summary)


class IdSet:
    """The distinct non-negative track ids seen, one bit each (a bitmap grown to the
    largest id): a live run reports ids for days, and a ``set`` of Python ints would cost
    some 60 octets an id for ever."""

    def __init__(self) -> None:
        self._bits = np.zeros(0, np.uint8)
        self._n = 0

    def update(self, ids: np.ndarray) -> None:
        """Add ``ids`` (integers ≥ 0)."""
        ids = np.asarray(ids, np.int64)
        if ids.size == 0:
            return
        if ids.min() < 0:
            raise ValueError(f"track ids must be >= 0, got {int(ids.min())}")
        need = int(ids.max()) // 8 + 1
        if need > self._bits.size:
            grown = np.zeros(max(need, 2 * self._bits.size), np.uint8)
            grown[:self._bits.size] = self._bits
            self._bits = grown
        ids = np.unique(ids)
        byte, bit = ids >> 3, (1 << (ids & 7)).astype(np.uint8)
        new = (self._bits[byte] & bit) == 0
        self._n += int(new.sum())
        np.bitwise_or.at(self._bits, byte[new], bit[new])

    def __len__(self) -> int:
        return self._n


def feed(outputs: Iterable[FrameOutput], sinks: Sequence[Sink], source: Source | None = None,
         *, backfill_ids: bool = True, summary: StatsSummary | None = None,
         keep_stats: bool = True) -> tuple[list[StepStats], int]:
    """Hand every frame's output to ``sinks`` (started with ``source`` first, closed
    after the last frame; on an error each is aborted, :meth:`Sink.abort`); returns the
    steps' statistics (none without ``keep_stats``; ``summary`` sums them) and the number
    of distinct track ids reported (with ``backfill_ids``, those of the backfill too)."""
    for sink in sinks:
        sink.start(source)
    stats: list[StepStats] = []
    ids = IdSet()
    try:
        for out in outputs:
            if keep_stats:
                stats.append(out.stats)
            if summary is not None:
                summary.add(out.stats)
            ids.update(out.online.track_id)
            if backfill_ids:
                ids.update(out.backfill.track_id)
            for sink in sinks:
                sink.write(out)
        for sink in sinks:
            sink.close()
    except BaseException:
        for sink in sinks:
            sink.abort()
        raise
    return stats, len(ids)
