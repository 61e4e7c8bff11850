"""A tracks file written as its rows become final, in bounded memory.

:class:`SortedRows` holds the rows of a ``history`` output until no later frame can
add a row before them: a backfill reaches at most ``MHTConfig.history_scans`` frames
back, so after a frame the rows of scans below :attr:`FrameOutput.settled
<mhtrack.sinks.base.FrameOutput.settled>` are final. Released in the order of
:meth:`TrackTable.sorted` (scan, then track id, stable): all rows of those scans have
arrived, and a stable sort of a prefix of scans is that prefix of the whole sort.

:class:`TrackRowsWriter` appends final rows to the file's atomic temporary
(:func:`~mhtrack.io.atomic.atomic_path`: named with the writer's pid, removed on an error,
on SIGTERM/SIGINT, and cleaned when stale) in chunks of ``chunk_rows`` rows — CSV lines,
or one Parquet row group each (``pyarrow.parquet.ParquetWriter``) — and moves it onto
the destination at :meth:`~TrackRowsWriter.commit`. The bytes are those
:func:`~mhtrack.io.tracks.write_track_rows` writes of all the rows at once with
``row_group_size = chunk_rows``: CSV cells and Parquet row groups depend only on their
own rows.
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

import numpy as np
import pyarrow as pa

from mhtrack.errors import InputError
from mhtrack.io._source import file_format
from mhtrack.io.atomic import OutputError, atomic_path, output_error
from mhtrack.io.tracks import track_columns, write_track_rows
from mhtrack.records import TrackTable

if TYPE_CHECKING:
    from mhtrack.models.geodesy import LocalFrame


class SortedRows:
    """Rows in, the same rows out in :meth:`TrackTable.sorted` order as they become final."""

    def __init__(self) -> None:
        self._pending: list[TrackTable] = []
        self._settled: int | None = None

    def push(self, rows: TrackTable, settled: int | None) -> TrackTable | None:
        """Keep ``rows``; the rows of scans below ``settled`` (sorted), if any."""
        if self._settled is not None and len(rows) and int(rows.scan.min()) < self._settled:
            raise RuntimeError(f"a row of scan {int(rows.scan.min())} came after scans "
                               f"below {self._settled} were written")
        if len(rows):
            self._pending.append(rows)
        if settled is None or not self._pending:
            return None
        self._settled = settled
        rows = TrackTable.concat(self._pending)
        final = rows.scan < settled
        if not final.any():
            self._pending = [rows]
            return None
        self._pending = [rows.take(~final)] if not final.all() else []
        return rows.take(final).sorted()

    def flush(self) -> TrackTable | None:
        """Every row kept (the end of the run), sorted."""
        rows, self._pending = self._pending, []
        return TrackTable.concat(rows).sorted() if rows else None


class TrackRowsWriter:
    """Rows appended in chunks to ``path``'s atomic temporary (module docstring); the file
    appears at :meth:`commit`, whole, or not at all (:meth:`abort`)."""

    def __init__(self, path: str | Path, frame: LocalFrame | None, *, timed: bool, iso: bool,
                 chunk_rows: int) -> None:
        if chunk_rows < 1:
            raise ValueError(f"chunk_rows must be at least 1, got {chunk_rows}")
        self.path, self.frame, self.timed, self.iso = Path(path), frame, timed, iso
        self.fmt = file_format(self.path)
        self.chunk_rows = chunk_rows
        self._buf: list[TrackTable] = []
        self._n_buf = 0
        self._atomic: Any = None  # the atomic_path context, once the first chunk is out
        self._fh: BinaryIO | None = None
        self._pq: Any = None
        self._attrs: bool | None = None  # attribute columns: set by the first chunk

    def add(self, rows: TrackTable | None) -> None:
        """Append ``rows`` (their ``plot`` the input's rows); whole chunks are written."""
        if rows is None or not len(rows):
            return
        self._buf.append(rows)
        self._n_buf += len(rows)
        if self._n_buf >= self.chunk_rows:
            rows = TrackTable.concat(self._buf)
            n = len(rows) - len(rows) % self.chunk_rows
            self._buf = [rows.take(np.arange(n, len(rows)))] if n < len(rows) else []
            self._n_buf = len(rows) - n
            for i in range(0, n, self.chunk_rows):
                self._chunk(rows.take(np.arange(i, i + self.chunk_rows)))

    def commit(self) -> None:
        """Write the rest and move the file onto ``path``."""
        rest = TrackTable.concat(self._buf) if self._buf else TrackTable.empty()
        self._buf, self._n_buf = [], 0
        if self._atomic is None:  # under one chunk: the file written at once
            write_track_rows(rest, self.path, self.frame, timed=self.timed, iso=self.iso,
                             row_group_size=self.chunk_rows)
            return
        if len(rest):
            self._chunk(rest)
        try:
            self._close_files()
            self._atomic.__exit__(None, None, None)
        except OSError as e:
            self._atomic = None
            raise self._error(e) from None
        self._atomic = None

    def abort(self) -> None:
        """Remove the temporary (the run failed); the file at ``path`` is left as it was."""
        self._buf, self._n_buf = [], 0
        if self._atomic is None:
            return
        with contextlib.suppress(Exception):
            self._close_files()
        with contextlib.suppress(_Aborted):
            self._atomic.__exit__(_Aborted, _Aborted(), None)
        self._atomic = None

    def _chunk(self, rows: TrackTable) -> None:
        if self._attrs is None:  # the first chunk decides the columns of the file
            self._attrs = rows.attrs is not None
        table = pa.table(track_columns(rows, self.fmt, self.frame, timed=self.timed,
                                       iso=self.iso, attrs=self._attrs))
        try:
            if self._atomic is None:
                self._open(table)
            if self._pq is not None:
                self._pq.write_table(table, row_group_size=self.chunk_rows)
            else:
                import pyarrow.csv as pacsv

                opts = pacsv.WriteOptions(include_header=False, quoting_style="none")
                pacsv.write_csv(table, self._fh, opts)
        except OSError as e:
            self.abort()
            raise self._error(e) from None

    def _open(self, table: pa.Table) -> None:
        self._atomic = atomic_path(self.path, make_parent=False)
        tmp = self._atomic.__enter__()
        self._fh = open(tmp, "wb")  # noqa: SIM115 - closed at commit or abort
        if self.fmt == "csv":
            self._fh.write((",".join(table.column_names) + "\n").encode())
        else:
            import pyarrow.parquet as pq

            self._pq = pq.ParquetWriter(self._fh, table.schema)

    def _close_files(self) -> None:
        if self._pq is not None:
            self._pq.close()
            self._pq = None
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def _error(self, e: OSError) -> InputError:
        """As :func:`~mhtrack.io._frame.write_frame` reports a failed write."""
        err = e if isinstance(e, OutputError) else output_error(self.path, e)
        return InputError(str(err), file=str(self.path))


class _Aborted(Exception):
    """Thrown into the atomic write to remove its temporary."""
