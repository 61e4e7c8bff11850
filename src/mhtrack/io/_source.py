"""A user's table file being read: its format from the extension, and errors that say
where (file, CSV line or Parquet row, column).

Internal machinery of :mod:`mhtrack.io.plots`, :mod:`~mhtrack.io.truth` and
:mod:`~mhtrack.io.tracks` (with :mod:`mhtrack.io._frame` and :mod:`mhtrack.io._checks`).
CSV line numbers are those a text editor shows (header = line 1); Parquet rows are 0-based.
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path

import numpy as np

from mhtrack.errors import InputError
from mhtrack.io.paths import check_input_file

PathArg = str | PathLike[str]

FORMATS = {".csv": "csv", ".parquet": "parquet"}


def file_format(path: PathArg) -> str:
    """``"csv"`` or ``"parquet"`` from the extension of ``path``; anything else is an error."""
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        shown = repr(suffix) if suffix else "no extension"
        raise InputError(
            f"{path}: unknown file type ({shown}); use a .csv or .parquet file",
            file=str(path),
        )
    return FORMATS[suffix]


class Source:
    """A file being read: its name as the user gave it, its format, and how to locate rows."""

    def __init__(self, path: PathArg) -> None:
        self.name = str(path)
        self.path = Path(path)
        self.format = file_format(path)
        self._lines: np.ndarray | None = None

    def check_readable(self) -> None:
        """Raise :class:`InputError` unless the path is a readable, non-empty file."""
        p = check_input_file(self.path)
        try:
            with p.open("rb") as fh:
                fh.read(1)
        except OSError as e:
            raise self.error(f"cannot read ({e.strerror or e})") from None
        if p.stat().st_size == 0:
            raise self.error("file is empty")

    def error(
        self,
        problem: str,
        *,
        row: int | None = None,
        column: str | None = None,
        line: int | None = None,
    ) -> InputError:
        """An :class:`InputError` for ``problem`` at data ``row`` (0-based) and ``column``."""
        where = [self.name]
        if row is not None and self.format == "csv" and line is None:
            line = self.line_of(row)
        if line is not None:
            where.append(f"line {line}")
        elif row is not None:
            where.append(f"row {row}" + (" (0-based)" if self.format == "parquet" else ""))
        if column is not None:
            where.append(f"column {column!r}")
        return InputError(
            ", ".join(where) + ": " + problem, file=self.name, line=line, row=row, column=column
        )

    def where(self, row: int) -> str:
        """``"line 17"`` (CSV) or ``"row 15"`` (Parquet) for data row ``row``."""
        if self.format == "csv":
            line = self.line_of(row)
            if line is not None:
                return f"line {line}"
        return f"row {row}"

    # -- CSV line numbers (computed only when an error needs one) ------------------------
    def _scan_lines(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        buf = np.frombuffer(self.path.read_bytes(), np.uint8)
        lf = buf == ord("\n")
        cr = buf == ord("\r")
        bare_cr = cr & ~np.concatenate((lf[1:], [False]))  # old-Mac line end
        nl = np.flatnonzero(lf | bare_cr)
        starts = np.concatenate(([0], nl + 1))
        ends = np.concatenate((nl, [buf.size]))
        length = ends - starts
        has = length > 0
        crlf = np.zeros(length.size, bool)
        crlf[has] = cr[ends[has] - 1]
        nonempty = np.flatnonzero(length - crlf > 0)  # pyarrow skips empty lines
        return buf, starts, ends, nonempty

    def line_at_offset(self, offset: int) -> tuple[int, int]:
        """(1-based line, 0-based field index) of byte ``offset`` of a CSV file."""
        buf, starts, _ends, _nonempty = self._scan_lines()
        i = int(np.searchsorted(starts, offset, side="right")) - 1
        field = int(np.count_nonzero(buf[starts[i] : offset] == ord(",")))
        return i + 1, field

    def line_of(self, row: int) -> int | None:
        """1-based line of data row ``row`` of a CSV file (the header is the first non-empty
        line), or ``None`` when it cannot be told."""
        if self._lines is None:
            self._lines = self._scan_lines()[3] + 1
        i = row + 1
        return int(self._lines[i]) if 0 <= i < self._lines.size else None

    def line_with_field_count_not(self, n_fields: int) -> int | None:
        """First data line whose number of comma-separated fields is not ``n_fields``
        (``None`` if the file has quotes, where counting commas is not reliable)."""
        buf, starts, ends, nonempty = self._scan_lines()
        if np.any(buf == ord('"')):
            return None
        commas = np.flatnonzero(buf == ord(","))
        data = nonempty[1:]
        count = np.searchsorted(commas, ends[data]) - np.searchsorted(commas, starts[data])
        bad = np.flatnonzero(count != n_fields - 1)
        return int(data[bad[0]]) + 1 if bad.size else None
