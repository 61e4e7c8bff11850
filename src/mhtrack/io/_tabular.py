"""Column tables in CSV or Parquet files, read with errors that say where.

Internal machinery for :mod:`mhtrack.io.plots`, :mod:`~mhtrack.io.truth` and
:mod:`~mhtrack.io.tracks`: choose the format from the file extension, parse with pyarrow,
turn every pyarrow or OS error into an :class:`~mhtrack.errors.InputError`, and offer
vectorised checks that report the first offending row (CSV: the line a text editor shows,
header = line 1; Parquet: the 0-based row index).
"""

from __future__ import annotations

import csv
import re
from collections.abc import Callable, Mapping, Sequence
from os import PathLike
from pathlib import Path
from typing import NoReturn

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from mhtrack.errors import InputError

PathArg = str | PathLike[str]

FORMATS = {".csv": "csv", ".parquet": "parquet"}
INT, FLOAT = "int", "float"

_CONVERSION = re.compile(
    r"In CSV column #(\d+): CSV conversion error to (\w+): invalid value '(.*)'", re.S
)
_FIELD_COUNT = re.compile(r"Expected (\d+) columns, got (\d+)")


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
        p = self.path
        if not p.exists():
            raise self.error("no such file")
        if p.is_dir():
            raise self.error("is a directory, not a file")
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


def _csv_header(src: Source) -> list[str]:
    """The first non-empty line (ended by ``\n``, ``\r\n`` or a lone ``\r``), parsed."""
    data = stripped = b""
    end = None
    with src.path.open("rb") as fh:
        while end is None:
            chunk = fh.read(1 << 16)
            data += chunk
            stripped = data.lstrip(b"\r\n")
            end = re.search(rb"[\r\n]", stripped)
            if not chunk:
                break
    if not stripped:
        raise src.error("file is empty (no header line)")
    raw = stripped[: end.start()] if end else stripped
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise src.error("header line is not valid UTF-8 text") from None
    return next(csv.reader([text]))


class Frame:
    """The columns of one file that a schema knows, as pyarrow arrays, with checks that
    convert them to NumPy and raise located :class:`InputError` on bad values."""

    def __init__(self, src: Source, table: pa.Table) -> None:
        self.src = src
        self.table = table
        self.n = table.num_rows

    def has(self, name: str) -> bool:
        return name in self.table.column_names

    def fail(self, problem: str, *, row: int | None = None, column: str | None = None) -> NoReturn:
        raise self.src.error(problem, row=row, column=column)

    def check(self, bad: np.ndarray, column: str | None, problem: Callable[[int], str]) -> None:
        """Raise for the first row where ``bad`` is true; ``problem(row)`` builds the text."""
        rows = np.flatnonzero(bad)
        if rows.size:
            row = int(rows[0])
            raise self.src.error(problem(row), row=row, column=column)

    def text(self, name: str, row: int) -> str:
        """Value of ``name`` at ``row`` as written in the file (CSV) or as Python shows it."""
        if self.src.format == "csv":
            opts = pacsv.ConvertOptions(
                include_columns=[name], column_types={name: pa.string()}, null_values=[]
            )
            col = pacsv.read_csv(self.src.path, convert_options=opts).column(0)
            return str(col[row].as_py())
        return repr(self.table.column(name)[row].as_py())

    def nulls(self, name: str) -> np.ndarray:
        """Boolean mask of the missing (empty / null) cells of column ``name``."""
        col = self.table.column(name)
        if col.null_count == 0:
            return np.zeros(self.n, bool)
        return col.is_null().to_numpy(zero_copy_only=False)

    def _no_nulls(self, name: str, nulls: np.ndarray) -> None:
        self.check(nulls, name, lambda row: "value is missing")

    def ints(self, name: str, *, nullable: bool = False, fill: int = -1) -> np.ndarray:
        """Column ``name`` as int64; missing cells are an error unless ``nullable`` (then
        ``fill``). Parquet float columns are accepted when every value is a whole number."""
        col = self.table.column(name)
        nulls = self.nulls(name)
        if not nullable:
            self._no_nulls(name, nulls)
        if pa.types.is_integer(col.type):
            try:
                col = col.cast(pa.int64())
            except pa.ArrowInvalid:  # uint64 beyond int64
                v = col.to_numpy(zero_copy_only=False)
                self.check(v > np.iinfo(np.int64).max, name, lambda r: f"value {v[r]} too large")
        elif pa.types.is_floating(col.type):
            v = col.to_numpy(zero_copy_only=False).astype(np.float64)
            whole = np.isfinite(v) & (v == np.round(v)) & (np.abs(v) < 2.0**63)
            self.check(
                ~whole & ~nulls, name, lambda r: f"value {self.text(name, r)!r} is not an integer"
            )
            col = pa.chunked_array([pa.array(np.where(nulls, 0, v).astype(np.int64), mask=nulls)])
        else:
            self.fail(f"has type {col.type}, expected integers", column=name)
        return col.fill_null(fill).to_numpy().astype(np.int64, copy=False)

    def floats(self, name: str, *, nullable: bool = False, finite: bool = True) -> np.ndarray:
        """Column ``name`` as float64, missing cells as NaN (an error unless ``nullable``);
        with ``finite``, NaN or infinite values written in the file are an error."""
        col = self.table.column(name)
        if not (pa.types.is_floating(col.type) or pa.types.is_integer(col.type)):
            self.fail(f"has type {col.type}, expected numbers", column=name)
        nulls = self.nulls(name)
        if not nullable:
            self._no_nulls(name, nulls)
        v = col.cast(pa.float64(), safe=False).fill_null(np.nan).to_numpy()
        if finite:
            self.check(
                ~np.isfinite(v) & ~nulls,
                name,
                lambda r: f"value {self.text(name, r)!r} is not finite",
            )
        return np.ascontiguousarray(v, dtype=np.float64)


def read_frame(
    path: PathArg, kinds: Mapping[str, str], required: Sequence[str], schema: str
) -> Frame:
    """Read the columns of ``kinds`` (name -> INT/FLOAT) that ``path`` has; the ``required``
    ones must all be there. Columns the schema does not know are ignored."""
    src = Source(path)
    src.check_readable()
    if src.format == "csv":
        names = _csv_header(src)
    else:
        try:
            names = pq.read_schema(src.path).names
        except (pa.ArrowException, OSError) as e:
            raise src.error(f"not a readable Parquet file ({e})") from None
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise src.error("appears twice in the header", column=name)
        seen.add(name)
    missing = [c for c in required if c not in seen]
    if missing:
        found = ", ".join(repr(c) for c in names)
        raise src.error(
            f"missing required column(s) {', '.join(repr(c) for c in missing)} "
            f"({schema} files need {', '.join(required)}; found {found})"
        )
    present = [c for c in kinds if c in seen]
    if src.format == "csv":
        types = {c: pa.int64() if kinds[c] == INT else pa.float64() for c in present}
        opts = pacsv.ConvertOptions(column_types=types, include_columns=present, null_values=[""])
        try:
            table = pacsv.read_csv(src.path, convert_options=opts)
        except pa.ArrowInvalid as e:
            raise _csv_error(src, names, str(e)) from None
        except (pa.ArrowException, OSError) as e:
            raise src.error(f"cannot read CSV ({e})") from None
    else:
        try:
            table = pq.read_table(src.path, columns=present)
        except (pa.ArrowException, OSError) as e:
            raise src.error(f"not a readable Parquet file ({e})") from None
    return Frame(src, table)


def _csv_error(src: Source, names: list[str], message: str) -> InputError:
    """Turn a pyarrow CSV error (which has no line number) into a located InputError."""
    if "invalid UTF8" in message or "\ufffd" in message:
        utf8 = _utf8_error(src, names)
        if utf8 is not None:
            return utf8
    m = _CONVERSION.search(message)
    if m and int(m[1]) < len(names):
        name, value = names[int(m[1])], m[3]
        what = "an integer" if m[2].startswith(("int", "uint")) else "a number"
        opts = pacsv.ConvertOptions(
            include_columns=[name], column_types={name: pa.string()}, null_values=[]
        )
        col = pacsv.read_csv(src.path, convert_options=opts).column(0)
        row = pc.index(col, value).as_py()
        return src.error(
            f"value {value!r} is not {what}", row=None if row < 0 else row, column=name
        )
    m = _FIELD_COUNT.search(message)
    if m:
        line = src.line_with_field_count_not(int(m[1]))
        return src.error(f"expected {m[1]} comma-separated fields, found {m[2]}", line=line)
    return src.error(f"cannot parse CSV ({message})")


def _utf8_error(src: Source, names: list[str]) -> InputError | None:
    """Locate the first byte that is not UTF-8 (pyarrow's error names only a column);
    ``None`` if the file is valid UTF-8 after all."""
    data = src.path.read_bytes()
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as e:
        line, field = src.line_at_offset(e.start)
        column = names[field] if field < len(names) else None
        byte = data[e.start]
        return src.error(f"not valid UTF-8 text (byte 0x{byte:02x})", line=line, column=column)
    return None


def write_frame(path: PathArg, columns: Mapping[str, pa.Array]) -> None:
    """Write ``columns`` (in order) to ``path`` as CSV or Parquet by its extension.

    CSV: a plain header line, then one line per row, numbers in shortest round-trip form,
    nulls as empty cells, nothing quoted."""
    fmt = file_format(path)
    table = pa.table(dict(columns))
    try:
        if fmt == "csv":
            with open(path, "wb") as fh:
                fh.write((",".join(table.column_names) + "\n").encode())
                opts = pacsv.WriteOptions(include_header=False, quoting_style="none")
                pacsv.write_csv(table, fh, opts)
        else:
            pq.write_table(table, str(path))
    except OSError as e:
        raise InputError(f"{path}: cannot write ({e.strerror or e})", file=str(path)) from None


def num(v: object) -> str:
    """A number for a message: integers as digits, floats in shortest round-trip form."""
    if isinstance(v, np.integer | int):
        return str(int(v))
    return repr(float(v))  # type: ignore[arg-type]


def check_scan_order(frame: Frame, scan: np.ndarray, time: np.ndarray) -> None:
    """Scans non-decreasing; one time per scan; times never going back from scan to scan."""
    if scan.size < 2:
        return
    src = frame.src
    after = np.concatenate(([False], scan[1:] < scan[:-1]))  # no np.diff: int64 overflow
    frame.check(
        after,
        "scan",
        lambda r: (
            f"scan {num(scan[r])} after scan {num(scan[r - 1])} ({src.where(r - 1)}); "
            "rows must be in non-decreasing scan order"
        ),
    )
    same = np.concatenate(([False], scan[1:] == scan[:-1]))
    changed = np.concatenate(([False], time[1:] != time[:-1]))
    back = np.concatenate(([False], time[1:] < time[:-1]))
    first = np.maximum.accumulate(np.where(same, 0, np.arange(scan.size)))

    def differs(r: int) -> str:
        f = int(first[r])
        return (
            f"time {num(time[r])} differs from time {num(time[f])} of scan {num(scan[r])} on "
            f"{src.where(f)}; all rows of a scan must have the same time"
        )

    frame.check(same & changed, "time", differs)
    frame.check(
        ~same & back,
        "time",
        lambda r: (
            f"time goes backwards: {num(time[r])} at scan {num(scan[r])} after "
            f"{num(time[r - 1])} at scan {num(scan[r - 1])} ({src.where(r - 1)})"
        ),
    )
    frame.check(
        ~same & ~changed & (np.arange(scan.size) > 0),
        "time",
        lambda r: (
            f"scan {num(scan[r])} has time {num(time[r])} s, not after scan "
            f"{num(scan[r - 1])}'s ({src.where(r - 1)}); times must strictly increase "
            "with scan number"
        ),
    )


def check_unique(frame: Frame, scan: np.ndarray, ids: np.ndarray, column: str) -> None:
    """No id twice within one scan (``scan`` already known to be sorted)."""
    if ids.size < 2:
        return
    order = np.lexsort((np.arange(ids.size), ids, scan))
    s, i = scan[order], ids[order]
    dup = (s[1:] == s[:-1]) & (i[1:] == i[:-1])
    rows = np.flatnonzero(dup)
    if rows.size:
        k = rows[np.argmin(order[rows + 1])]  # lexsort keeps file order among equal keys
        earlier, later = int(order[k]), int(order[k + 1])
        raise frame.src.error(
            f"{column} {num(ids[later])} appears twice in scan {num(scan[later])} "
            f"(also on {frame.src.where(earlier)})",
            row=later,
            column=column,
        )


def int_array(values: np.ndarray, missing: np.ndarray | None = None) -> pa.Array:
    """int64 array for writing; ``missing`` rows become nulls (empty CSV cells)."""
    return pa.array(np.asarray(values, np.int64), type=pa.int64(), mask=missing)


def float_array(values: np.ndarray, *, nan_as_null: bool = False) -> pa.Array:
    """float64 array for writing; with ``nan_as_null`` NaN becomes a null (empty CSV cell)."""
    v = np.asarray(values, np.float64)
    return pa.array(v, type=pa.float64(), mask=np.isnan(v) if nan_as_null else None)
