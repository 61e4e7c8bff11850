"""The sink interface: what the tracker reports, one frame at a time.

A pipeline (:class:`mhtrack.pipeline.Pipeline`) steps the tracker over a source's frames
and hands every sink one :class:`FrameOutput` per frame: the rows the tracker reported at
that frame (``online``) and, kept apart, the tentative past of the tracks confirmed at
it (``backfill``, :attr:`~mhtrack.mht.MHTTracker.last_backfill`). The output mode
(:data:`mhtrack.names.OUTPUTS`) decides what a table keeps: ``history`` both, sorted by
scan and track at the end; ``online`` only the online rows, in the order reported —
the rows :meth:`~mhtrack.mht.MHTTracker.run` returns; ``smoothed`` the rows of
``history``, which the pipeline smooths before the sinks see them
(:class:`~mhtrack.sinks.smoothed.SmoothedHistory`): a sink keeps them as ``history``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from mhtrack.names import DEFAULT_OUTPUT, OUTPUTS
from mhtrack.records import Scan, TrackTable

if TYPE_CHECKING:
    from mhtrack.mht.report import StepStats
    from mhtrack.sources.base import Source


@dataclass(frozen=True)
class FrameOutput:
    """What one tracker step produced."""

    #: The frame (scan) the tracker stepped, after any fusion.
    frame: Scan
    #: The confirmed tracks of the best hypothesis at this frame.
    online: TrackTable
    #: Earlier rows of the tracks confirmed at this frame (``tentative`` true).
    backfill: TrackTable
    #: The step's statistics, with the fusion's caps merged in.
    stats: StepStats
    #: Every later output's rows have ``scan`` at least this (the backfill reaches back
    #: ``MHTConfig.history_scans`` frames at most); ``None``: unknown.
    settled: int | None = None


class Sink(ABC):
    """Receives every frame's output; :meth:`start` before the first, :meth:`close`
    after the last (a file sink writes there)."""

    #: The sink keeps a table of the rows (a tracks file, a collector): with the output
    #: ``smoothed`` it gets the smoothed rows, other sinks each frame's output.
    keeps_rows: ClassVar[bool] = False

    def start(self, source: Source | None) -> None:  # noqa: B027 - optional hook
        """Called once before the first frame with the source (its ``file_rows``,
        ``timed``); ``None`` when the frames come from no source (rows kept as they
        are, scans)."""

    @abstractmethod
    def write(self, out: FrameOutput) -> None:
        """One frame's output."""

    def close(self) -> None:  # noqa: B027 - optional hook
        """Called once after the last frame."""

    def abort(self) -> None:  # noqa: B027 - optional hook
        """Called instead of :meth:`close` when the run fails: a file sink removes what
        it has half written (the file is left as it was)."""


def check_output(output: str | None) -> str:
    """``output`` (default :data:`DEFAULT_OUTPUT`), checked against :data:`OUTPUTS`."""
    output = DEFAULT_OUTPUT if output is None else output
    if output not in OUTPUTS:
        raise ValueError(f"unknown output {output!r} (expected one of {', '.join(OUTPUTS)})")
    return output


class TrackCollector(Sink):
    """The tracks of the whole run in memory, as :meth:`MHTTracker.run` returns them."""

    keeps_rows = True

    def __init__(self, output: str | None = None) -> None:
        self.output = check_output(output)
        self._parts: list[TrackTable] = []

    def write(self, out: FrameOutput) -> None:
        self._parts += [t for t in (out.online, out.backfill if self.output != "online"
                                    else None) if t is not None and len(t)]

    def tracks(self) -> TrackTable:
        """The rows so far (``history``, ``smoothed``: sorted by scan, then track id)."""
        out = TrackTable.concat(self._parts)
        return out if self.output == "online" else out.sorted()

    def clear(self) -> None:
        """Forget the rows so far (a rolling part was written)."""
        self._parts = []


class CallbackSink(Sink):
    """Calls ``fn(out)`` with every frame's :class:`FrameOutput` (a library user's hook;
    :meth:`mhtrack.pipeline.Pipeline.outputs` is the same stream as an iterator)."""

    def __init__(self, fn: Callable[[FrameOutput], object]) -> None:
        self.fn = fn

    def write(self, out: FrameOutput) -> None:
        self.fn(out)
