"""Timed plots in arrival order → frames in processing order: the re-order buffer
(:mod:`~mhtrack.io.reorder`), then the framer (:mod:`~mhtrack.sources.framer`),
then :class:`~mhtrack.records.Scan` frames with running row numbers. Shared by every
source of timed plots (tables, recordings, datagrams)."""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator, Mapping

import numpy as np

from mhtrack.attributes import of_columns
from mhtrack.io.reorder import ReorderBuffer
from mhtrack.records import Scan
from mhtrack.sources.base import SourceStats
from mhtrack.sources.framer import Frame, Framer


class TimedStream:
    """Batches of plots (columns ``time, sensor, x, y, file_row`` and optionally ``R``,
    ``origin`` and the attribute columns of :data:`mhtrack.attributes.COLUMNS`; arrival
    order) in, :class:`Scan` frames out.

    ``Scan.rows`` number the plots 0, 1, … in the order they are yielded;
    :meth:`file_rows` maps them to the batches' ``file_row``. ``stats`` is updated as
    plots pass; :meth:`finish` logs one warning line if plots were dropped, naming the
    first by ``where(its column values)``."""

    def __init__(self, name: str, stats: SourceStats, frame_s: Mapping[int, float] | float,
                 window_s: float, where: Callable[[dict[str, object]], str], *,
                 first_frame: int = 0, first_row: int = 0,
                 not_before: float | None = None, keep_rows: int | None = None,
                 release: str = "time") -> None:
        self.name = name
        self.stats = stats
        self.where = where
        self.buffer = ReorderBuffer(window_s)
        self.framer = Framer(frame_s, release=release)  # when frames go out
        self.framer.n_frames = int(first_frame)  # frames numbered on from here
        if not_before is not None:  # as if plots up to it had gone: earlier ones are late
            self.buffer.latest = self.buffer.released = float(not_before)
            self.framer.last_time = float(not_before)  # and frame times go on from it
        # file row of each running row: one int64 array grown by doubling (8 bytes a
        # plot, no object per frame), the first ``_n_out`` entries valid; with
        # ``keep_rows`` (a stream without end: live) a ring of the last ``keep_rows``
        # rows, allocated and written whole at the start (memory flat)
        if keep_rows is not None and keep_rows < 1:
            raise ValueError(f"keep_rows must be >= 1, got {keep_rows!r}")
        self.keep_rows = keep_rows
        self._rows = np.zeros(1024, np.int64) if keep_rows is None else \
            np.full(int(keep_rows), -1, np.int64)
        self._n_out = 0
        #: Times the input went quiet (:meth:`idle`).
        self.idles = 0
        #: The first running row number (a resumed run numbers on: the tracker's plot
        #: windows hold the earlier run's rows, and a plot is known by its row).
        self.first_row = int(first_row)

    def push(self, cols: Mapping[str, np.ndarray]) -> Iterator[Scan]:
        """Frames completed by one more batch of plots (and sweep marks: rows with
        ``mark`` true, :mod:`~mhtrack.sources.marks`)."""
        if not cols:
            return
        self.stats.plots_in += _plots(cols)
        released = self.buffer.push(cols)
        self._count()
        if released and len(released["time"]):
            yield from map(self._scan, self.framer.push(released))

    def _release_all(self) -> Iterator[Scan]:
        """Every plot held: the re-order window released, every open frame closed."""
        released = self.buffer.flush()
        if released and len(released["time"]):
            yield from map(self._scan, self.framer.push(released))
        yield from map(self._scan, self.framer.flush())
        self._count()

    def finish(self) -> Iterator[Scan]:
        """The remaining frames (end of input); warns about dropped plots."""
        yield from self._release_all()
        log = logging.getLogger("mhtrack")
        for late, what in ((self.buffer.late, "plot"),
                           (self.buffer.late_marks, "sector crossing")):
            if late.n:
                log.warning("%s", late.line(self.name, self.where(late.first), what))

    def idle(self) -> Iterator[Scan]:
        """The input went quiet (a live feed: :data:`~mhtrack.sources.base.IDLE`): the
        re-order window is released and every open frame closed, as at the end of the
        input, but the stream goes on — a later plot older than the plots released is a
        late drop, a later plot of a radar starts its next frame."""
        self.idles += 1
        yield from self._release_all()

    def pending(self) -> dict[str, object]:
        """The plots held — in the framer (``framed``) and in the re-order buffer
        (``held``), columns or ``None`` — and the buffer's ``latest`` and ``released``
        times: with :meth:`restore`, a later stream goes on as this one would have."""
        b = self.buffer
        return {"framed": self.framer.pending(), "held": b.held(), "latest": b.latest,
                "released": b.released}

    def restore(self, pending: Mapping[str, object]) -> Iterator[Scan]:
        """Take the plots of another stream's :meth:`pending` back (before any push):
        the framed ones straight into the framer, the held ones into the buffer; the
        frames already complete (a checkpoint taken between two frames of one push)."""
        b = self.buffer
        b.latest, b.released = float(pending["latest"]), float(pending["released"])  # type: ignore[arg-type]
        framed, held = pending.get("framed"), pending.get("held")
        for c in (framed, held):
            self.stats.plots_in += 0 if c is None else _plots(c)  # type: ignore[arg-type]
        if framed is not None:
            yield from map(self._scan, self.framer.push(framed))  # type: ignore[arg-type]
        if held is not None:  # all within the window of ``latest``: none should leave
            reordered = b.reordered
            released = b.push(held)  # type: ignore[arg-type]
            b.reordered = reordered
            if released and len(released["time"]):
                yield from map(self._scan, self.framer.push(released))

    def _count(self) -> None:
        b, s = self.buffer, self.stats
        s.reordered, s.late_dropped, s.max_late_s = b.reordered, b.late.n, b.late.max_late_s
        s.late_crossings = b.late_marks.n

    def _scan(self, fr: Frame) -> Scan:
        c = fr.cols
        n = len(c["time"])
        rows = np.arange(self._n_out, self._n_out + n, dtype=np.int64) + self.first_row
        if self.keep_rows is not None:  # the last keep_rows of the frame's rows
            last = np.arange(max(0, n - self.keep_rows), n)
            self._rows[(self._n_out + last) % self.keep_rows] = \
                np.asarray(c["file_row"], np.int64)[last]
        elif self._n_out + n > self._rows.size:
            grown = np.zeros(max(2 * self._rows.size, self._n_out + n), np.int64)
            grown[:self._n_out] = self._rows[:self._n_out]
            self._rows = grown
        if self.keep_rows is None:
            self._rows[self._n_out:self._n_out + n] = c["file_row"]
        self._n_out += n
        self.stats.plots_out += n
        self.stats.frames += 1
        return Scan(index=fr.index, time=fr.time, z=np.column_stack((c["x"], c["y"])),
                    sensor=np.asarray(c["sensor"], np.int64), rows=rows, R=c.get("R"),
                    origin=c.get("origin"), t=np.asarray(c["time"], float),
                    attrs=of_columns(c), closing=_closing(fr))

    @property
    def next_row(self) -> int:
        """The running row number of the next plot."""
        return self.first_row + self._n_out

    def file_rows(self, rows: np.ndarray) -> np.ndarray:
        """The ``file_row`` of each running row number (``-1`` stays ``-1``, and so
        does a row before :attr:`first_row` or, with ``keep_rows``, one older than the
        last ``keep_rows``)."""
        rows = np.asarray(rows, np.int64) - self.first_row
        out = np.full(rows.shape, -1, np.int64)
        if self.keep_rows is None:
            ok = rows >= 0
            out[ok] = self._rows[:self._n_out][rows[ok]]
        else:
            ok = (rows >= max(0, self._n_out - self.keep_rows)) & (rows < self._n_out)
            out[ok] = self._rows[rows[ok] % self.keep_rows]
        return out


def _plots(cols: Mapping[str, np.ndarray]) -> int:
    """The number of plots among the rows ``cols`` (sweep marks, ``mark`` true, are no
    plots)."""
    n = len(cols["time"])
    return n - int(np.count_nonzero(cols["mark"])) if "mark" in cols else n


def _closing(fr: Frame) -> int | None:
    """The byte offset of the sweep mark that closed ``fr`` (``Scan.closing``); ``None``
    if none did or its offset is unknown (a mark restored from a checkpoint)."""
    at = -1 if fr.mark is None else int(fr.mark.get("offset", -1))  # type: ignore[call-overload]
    return at if at >= 0 else None
