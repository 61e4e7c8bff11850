"""The source interface: plots that reach the tracker one frame at a time, in time order.

A :class:`Source` is where plots come from — a plots table (CSV or Parquet), an ASTERIX
recording, or any iterable of datagrams (a socket reader). Iterating over it yields
:class:`~mhtrack.records.Scan` frames lazily, in the order the tracker must process them
(``docs/architecture.md``, *Sources, frames, tracker, sinks*):

* a synchronous plots table (a ``scan`` column) yields one scan per scan index;
* timed plots (each with its own time and sensor) are re-ordered within a bounded window,
  cut into one-sensor frames (:mod:`mhtrack.frames`) and yielded as each frame completes.

Ordering is the source's job: plots that arrive out of time order by at most the reorder
window are re-ordered; later ones are dropped and counted (:class:`SourceStats`), never a
refusal of the whole input. ``Scan.rows`` are running row numbers in the order the plots
are yielded (what tracks refer to); :meth:`Source.file_rows` maps them back to the rows
(or plots, for a recording) of the user's own input.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.records import Scan

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet
    from mhtrack.scenario import Scenario


class _Idle:
    """The type of :data:`IDLE`."""

    def __repr__(self) -> str:
        return "IDLE"


#: In a live stream of datagrams, in place of one: the input has been quiet for a
#: bounded wall-clock wait (a reader's ``idle_s``, :mod:`~mhtrack.sources.udp`); a
#: :class:`~mhtrack.sources.datagrams.DatagramSource` then closes the frames it holds.
IDLE = _Idle()


class _CaughtUp:
    """The type of :data:`CAUGHT_UP`."""

    def __repr__(self) -> str:
        return "CAUGHT_UP"


#: In a live stream of datagrams, after one: no other datagram is waiting now; a
#: :class:`~mhtrack.sources.datagrams.DatagramSource` passes on the plots it has decoded
#: (a live feed decodes what has queued up as one chunk, not datagram by datagram; the
#: frames do not depend on the chunks, only when they are given out).
CAUGHT_UP = _CaughtUp()


@dataclass
class SourceStats:
    """What a source did to its input so far (counters only grow while it is read)."""

    #: Plots read from the input (before any is dropped).
    plots_in: int = 0
    #: Plots yielded to the tracker in frames.
    plots_out: int = 0
    #: Frames (or scans) yielded.
    frames: int = 0
    #: Plots that arrived out of time order within the reorder window and were re-ordered.
    reordered: int = 0
    #: Plots dropped because they arrived later than the reorder window allows.
    late_dropped: int = 0
    #: The largest lateness (s) of a dropped plot.
    max_late_s: float = 0.0
    #: A radar's sector crossings (CAT034/CAT002 north markers and sector crossings:
    #: sweep marks, ``sectors`` frames) dropped for arriving later than the reorder window
    #: allows — no plots, so not in :attr:`late_dropped`; the frame they would have
    #: closed closes by the rules without one (``docs/live.md``).
    late_crossings: int = 0
    #: Other counts by kind (e.g. ``"duplicate datagrams"``, ``"no position"``).
    skipped: dict[str, int] = field(default_factory=dict)


@dataclass(frozen=True)
class Survey:
    """What a finished input holds, found before tracking (for the defaults that need the
    whole input: the surveillance area, the radars' rotation periods). ``None`` fields are
    unknown (a live source has no survey)."""

    #: Number of plots.
    n_plots: int
    #: Sensor ids that occur in the plots.
    sensors: tuple[int, ...]
    #: ``x`` and ``y`` (m, the local frame) of every plot, for the robust bounding box of
    #: :func:`mhtrack.build.plots_area`; ``None`` if the source cannot give them.
    x: np.ndarray | None = None
    y: np.ndarray | None = None
    #: Number of frames (or scans) the source will yield, when known (progress bars).
    n_frames: int | None = None
    #: Each plot's sensor id and time (s), aligned with ``x, y``, for the defaults of
    #: rotating radars (:func:`mhtrack.build.radar_rule`); ``None`` if not given.
    sensor: np.ndarray | None = None
    time: np.ndarray | None = None


class Source(ABC):
    """Plots from one input, yielded as frames in processing order.

    Attributes
    ----------
    name : the input as the user named it (a path, ``"udp://…"``); errors name it.
    timed : whether the plots carry their own times (frames of one sensor each) rather
        than synchronous scans.
    iso_times : whether the input wrote its times as ISO-8601 (the tracks then are too).
    sensors : the sensors' sites, errors and periods (timed plots, recordings), or
        ``None``.
    scenario : the scenario giving the sensors and every scan time (synchronous tables
        with a scenario), or ``None``.
    stats : what the source has done so far (:class:`SourceStats`).
    """

    name: str
    timed: bool
    #: The input's times were ISO-8601 text or timestamps (tracks are written so too).
    iso_times: bool = False
    sensors: SensorSet | None = None
    scenario: Scenario | None = None
    #: Draw a progress bar over :meth:`survey`'s pass where the source can count it (a
    #: recording: its bytes; :class:`~mhtrack.progress.Count`).
    progress: bool = False

    def __init__(self) -> None:
        self.stats = SourceStats()

    @abstractmethod
    def __iter__(self) -> Iterator[Scan]:
        """The frames, lazily, in processing order (each frame's plots in time order)."""

    @abstractmethod
    def file_rows(self, rows: np.ndarray) -> np.ndarray:
        """The input's own row (plots table: 0-based data row; recording: 0-based plot in
        decoding order) of each running row number in ``rows``; ``-1`` stays ``-1``."""

    def survey(self) -> Survey | None:
        """What the whole input holds, when it is a finished file; ``None`` for a live
        source. May read the input once more (without keeping its plots)."""
        return None
