"""File sinks: a tracks table (CSV or Parquet) and a CAT062 recording, each written
atomically (:mod:`mhtrack.io.atomic`) — at the end, or for a table in rolling parts."""

from __future__ import annotations

import dataclasses
from abc import abstractmethod
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.io.tracks import ROW_GROUP, write_track_rows
from mhtrack.records import TrackTable
from mhtrack.sinks.base import FrameOutput, Sink, TrackCollector
from mhtrack.sinks.spill import SortedRows, TrackRowsWriter

if TYPE_CHECKING:
    from mhtrack.models.geodesy import LocalFrame
    from mhtrack.sources.base import Source


class _Rows(Sink):
    """Collects the rows an output mode keeps and the source's row mapping; with
    ``part_frames = n`` writes them every ``n`` frames to ``STEM.part0000.SUFFIX``, … of
    ``path`` (:meth:`_write_part`, each part atomically), :attr:`paths` the files written."""

    keeps_rows = True

    def __init__(self, output: str | None, path: str | Path,
                 part_frames: int | None) -> None:
        if part_frames is not None and part_frames < 1:
            raise ValueError(f"part_frames must be at least 1, got {part_frames}")
        self.rows = TrackCollector(output)
        self.source: Source | None = None
        self.path, self.part_frames = Path(path), part_frames
        self.paths: list[Path] = []
        self._frames = 0

    def start(self, source: Source | None) -> None:
        self.source = source

    def write(self, out: FrameOutput) -> None:
        self.rows.write(out)

    def _part_frame(self, out: FrameOutput) -> None:
        """Rolling parts: keep the frame's rows; a part is written every ``n`` frames."""
        self.rows.write(out)
        if self._frames % self.part_frames == 0:  # type: ignore[operator]
            self._flush()

    def _last_part(self) -> None:
        """Rolling parts at the end: the frames since the last part (or one empty part)."""
        if self._frames % self.part_frames or not self.paths:  # type: ignore[operator]
            self._flush()

    def _flush(self) -> None:
        p = self.path
        self._write_part(p.with_name(f"{p.stem}.part{len(self.paths):04d}{p.suffix}"))
        self.rows.clear()

    @abstractmethod
    def _write_part(self, path: Path) -> None:
        """Write the collected rows as the part file ``path`` (atomically)."""

    def _file_rows(self, tracks: TrackTable) -> TrackTable:
        """``tracks`` with ``plot`` as the input's own rows (:meth:`Source.file_rows`)."""
        if self.source is None:
            return tracks
        return dataclasses.replace(tracks, plot=np.asarray(self.source.file_rows(tracks.plot),
                                                           np.int64))


class TracksFileSink(_Rows):
    """The tracks file (``docs/file-formats.md``): the rows of ``output`` (history or
    online), ``plot`` naming the input's rows, ``lat, lon`` and east/north velocities with
    ``frame``; ``frame`` in place of ``scan`` for timed input.

    Without ``part_frames`` the file appears once, atomically, at the end — the bytes
    :func:`~mhtrack.io.write_tracks` writes of the whole run — but its rows are written
    to its temporary as they become final, ``chunk_rows`` at a time
    (:mod:`mhtrack.sinks.spill`), so memory stays flat in the run's length. With
    ``part_frames = n``, every ``n`` frames the rows produced in them (online rows, and
    with ``history`` the backfill of the tracks confirmed in them, which may lie in
    earlier parts' frames) go to ``STEM.part0000.SUFFIX``, ``STEM.part0001.SUFFIX``, …,
    each written atomically and each sorted as a whole run's rows are; :attr:`paths`
    lists the files written."""

    def __init__(self, path: str | Path, *, frame: LocalFrame | None = None,
                 output: str | None = None, part_frames: int | None = None,
                 chunk_rows: int = ROW_GROUP) -> None:
        super().__init__(output, path, part_frames)
        if chunk_rows < 1:
            raise ValueError(f"chunk_rows must be at least 1, got {chunk_rows}")
        self.frame, self.chunk_rows = frame, chunk_rows
        self._sorter = SortedRows()
        self._writer: TrackRowsWriter | None = None

    def start(self, source: Source | None) -> None:
        super().start(source)
        if self.part_frames is None:
            self._writer = TrackRowsWriter(self.path, self.frame, timed=self._timed,
                                           iso=self._iso, chunk_rows=self.chunk_rows)

    @property
    def _timed(self) -> bool:
        return self.source is not None and self.source.timed

    @property
    def _iso(self) -> bool:
        return self.source is not None and self.source.iso_times

    def write(self, out: FrameOutput) -> None:
        self._frames += 1
        if self.part_frames is not None:
            self._part_frame(out)
            return
        if self._writer is None:
            self.start(None)
        assert self._writer is not None
        history = self.rows.output != "online"
        rows = [t for t in (out.online, out.backfill if history else None)
                if t is not None and len(t)]
        if not rows:
            new = TrackTable.empty()
        else:  # the input's own rows now (the source may forget older ones); no P kept
            new = self._file_rows(dataclasses.replace(TrackTable.concat(rows), P=None))
        if history:
            self._writer.add(self._sorter.push(new, out.settled))
        else:
            self._writer.add(new)

    def close(self) -> None:
        if self.part_frames is None:
            if self._writer is None:
                self.start(None)
            assert self._writer is not None
            self._writer.add(self._sorter.flush())
            self._writer.commit()
            self.paths.append(self.path)
        else:
            self._last_part()

    def abort(self) -> None:
        if self._writer is not None:
            self._writer.abort()

    def _write_part(self, path: Path) -> None:
        write_track_rows(self._file_rows(self.rows.tracks()), path, self.frame,
                         timed=self._timed, iso=self._iso)
        self.paths.append(path)


def cat062_blocks(tracks: TrackTable, frame: LocalFrame, name: str, *,
                  sac: int | None = None, sic: int | None = None
                  ) -> Iterator[tuple[float, int, bytes]]:
    """``(time, data source, CAT062 data block)`` of tracker rows ``tracks``: the
    encoding path of every CAT062 sink — the octets libasterix writes of
    :func:`~mhtrack.io.asterix.cat062.table_messages`
    (:func:`~mhtrack.io.asterix.encode.encode_blocks`, at most 40 records a block),
    encoded with NumPy (:func:`~mhtrack.io.asterix.cat062_fast.blocks062`, through
    ``row_blocks``, which ``export --category 062`` uses too)."""
    from mhtrack.io.asterix.cat062_fast import blocks062

    return blocks062(tracks, frame, name, sac=sac, sic=sic)


class Cat062Sink(_Rows):
    """The tracks as ASTERIX CAT062 system tracks from data source ``sac``/``sic``
    (:func:`cat062_blocks`; positions through ``frame``), written atomically to a
    ``.pcap`` or raw ``.ast`` file: at the end, the bytes ``mhtrack export TRACKS
    --category 062`` writes of the tracks file of the same rows; or, with ``part_frames
    = n``, every ``n`` frames the rows of those frames to ``STEM.part0000.SUFFIX``, … (as
    :class:`TracksFileSink`; a part with no rows is an empty recording). A run with no
    rows at all is an error, unless ``empty_ok`` (a live run stopped before any track:
    an empty recording)."""

    def __init__(self, path: str | Path, frame: LocalFrame, *, output: str | None = None,
                 sac: int | None = None, sic: int | None = None,
                 part_frames: int | None = None, empty_ok: bool = False) -> None:
        super().__init__(output, path, part_frames)
        self.frame, self.sac, self.sic, self.empty_ok = frame, sac, sic, empty_ok
        self.n_blocks = 0

    def write(self, out: FrameOutput) -> None:
        self._frames += 1
        if self.part_frames is not None:
            self._part_frame(out)
        else:
            super().write(out)

    def close(self) -> None:
        if self.part_frames is not None:
            self._last_part()
            return
        tracks = self.rows.tracks()
        if len(tracks) == 0 and not self.empty_ok:
            raise ValueError(f"{self.path}: no track rows (nothing to export)")
        self._write(self.path, tracks)

    def _write_part(self, path: Path) -> None:
        self._write(path, self.rows.tracks())

    def _write(self, path: Path, tracks: TrackTable) -> None:
        from mhtrack.io.asterix.writer import write_blocks

        self.n_blocks += write_blocks(path, cat062_blocks(tracks, self.frame, str(path),
                                                          sac=self.sac, sic=self.sic))
        self.paths.append(path)
