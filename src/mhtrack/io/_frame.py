"""Column tables in CSV or Parquet files: read with located errors, and written.

:func:`read_frame` parses a file with pyarrow and turns every pyarrow or OS error into a
located :class:`~mhtrack.errors.InputError`; :class:`Frame` converts its columns to NumPy
with vectorised checks that report the first offending row; :func:`write_frame` writes
columns as CSV (shortest round-trip numbers) or Parquet, atomically.
"""

from __future__ import annotations

import csv
import re
from collections.abc import Callable, Mapping, Sequence
from typing import NoReturn

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv

from mhtrack.bounds import (
    MAX_COLUMNS,
    MAX_INDEX,
    MAX_LINE_BYTES,
    MAX_MAGNITUDE,
    MAX_TIME_S,
    clip,
    float_range,
    int_range,
)
from mhtrack.errors import InputError
from mhtrack.io._arrow import from_numpy, is_null, to_numpy
from mhtrack.io._source import PathArg, Source, file_format
from mhtrack.io.atomic import OutputError, atomic_path
from mhtrack.io.paths import arrow_file

#: Column kinds of a schema: integers, floats, and times (read as they are written —
#: text in CSV, any type in Parquet — and converted by :mod:`mhtrack.io._times`).
INT, FLOAT, TIME = "int", "float", "time"

_CONVERSION = re.compile(
    r"In CSV column #(\d+): CSV conversion error to (\w+): invalid value '(.*)'", re.S
)
_FIELD_COUNT = re.compile(r"Expected (\d+) columns, got (\d+)")
#: Largest |value| of a float column, by name (``mhtrack.bounds``); others MAX_MAGNITUDE.
FLOAT_BOUNDS = {"time": MAX_TIME_S}


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
            if end is None and len(stripped) > MAX_LINE_BYTES:
                n = stripped.count(b",") + 1
                if n > MAX_COLUMNS:
                    raise src.error(f"header has more than {n} columns, more than the "
                                    f"{MAX_COLUMNS} allowed", line=1)
                raise src.error(f"header line is longer than {MAX_LINE_BYTES} bytes "
                                f"(expected at most {MAX_COLUMNS} short column names)",
                                line=1)
    if not stripped:
        raise src.error("file is empty (no header line)")
    raw = stripped[: end.start()] if end else stripped
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise src.error("header line is not valid UTF-8 text") from None
    return next(csv.reader([text]))


def _check_width(src: Source, names: list[str]) -> None:
    if len(names) > MAX_COLUMNS:
        raise src.error(f"header has {len(names)} columns, more than the {MAX_COLUMNS} "
                        "allowed", line=1 if src.format == "csv" else None)


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
            with arrow_file(self.src.path) as fh:
                col = pacsv.read_csv(fh, convert_options=opts).column(0)
            return str(col[row].as_py())
        return repr(self.table.column(name)[row].as_py())

    def nulls(self, name: str) -> np.ndarray:
        """Boolean mask of the missing (empty / null) cells of column ``name``."""
        return is_null(self.table.column(name))

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
                self.check(v > MAX_INDEX, name, lambda r: f"value {v[r]} is out of range "
                           f"(expected {int_range(-MAX_INDEX, MAX_INDEX)})")
        elif pa.types.is_floating(col.type):
            v = to_numpy(col.cast(pa.float64()), fill=np.nan)
            whole = np.isfinite(v) & (v == np.round(v))
            self.check(
                ~whole & ~nulls, name,
                lambda r: f"value {clip(repr(self.text(name, r)))} is not an integer",
            )
            self.check(
                (np.abs(v) > MAX_INDEX) & ~nulls, name,
                lambda r: f"value {clip(self.text(name, r))} is out of range (expected "
                f"{int_range(-MAX_INDEX, MAX_INDEX)})",
            )
            col = from_numpy(np.where(nulls, 0, v), pa.int64(), nulls)
        else:
            self.fail(f"has type {col.type}, expected integers", column=name)
        v = to_numpy(col, fill=fill)
        self.check(
            ((v > MAX_INDEX) | (v < -MAX_INDEX)) & ~nulls, name,  # no np.abs: -2^63
            lambda r: f"value {clip(self.text(name, r))} is out of range (expected "
            f"{int_range(-MAX_INDEX, MAX_INDEX)})",
        )
        return v

    def floats(self, name: str, *, nullable: bool = False, finite: bool = True) -> np.ndarray:
        """Column ``name`` as float64, missing cells as NaN (an error unless ``nullable``);
        with ``finite``, NaN or infinite values written in the file are an error."""
        col = self.table.column(name)
        if not (pa.types.is_floating(col.type) or pa.types.is_integer(col.type)):
            self.fail(f"has type {col.type}, expected numbers", column=name)
        nulls = self.nulls(name)
        if not nullable:
            self._no_nulls(name, nulls)
        v = to_numpy(col.cast(pa.float64(), safe=False), fill=np.nan)
        if finite:
            self.check(
                ~np.isfinite(v) & ~nulls,
                name,
                lambda r: f"value {clip(repr(self.text(name, r)))} is not finite",
            )
        return self.bounded(name, np.ascontiguousarray(v, dtype=np.float64))

    def bounded(self, name: str, v: np.ndarray) -> np.ndarray:
        """``v`` (column ``name``), its finite values checked within ±the column's bound
        (:data:`FLOAT_BOUNDS`, else ``MAX_MAGNITUDE``)."""
        hi = FLOAT_BOUNDS.get(name, MAX_MAGNITUDE)
        with np.errstate(invalid="ignore"):
            bad = np.isfinite(v) & (np.abs(v) > hi)
        self.check(bad, name, lambda r: f"value {clip(self.text(name, r))} is out of range "
                   f"(expected {float_range(-hi, hi)})")
        return v


def column_names(path: PathArg) -> list[str]:
    """The column names of a CSV or Parquet file, in file order (located errors)."""
    src = Source(path)
    src.check_readable()
    return _column_names(src)


def _column_names(src: Source) -> list[str]:
    if src.format == "csv":
        names = _csv_header(src)
    else:
        import pyarrow.parquet as pq  # only for Parquet files (fast start)

        try:
            with arrow_file(src.path) as fh:
                names = pq.read_schema(fh).names
        except (pa.ArrowException, OSError) as e:
            raise src.error(f"not a readable Parquet file ({clip(str(e), 200)})") from None
    _check_width(src, names)
    return names


def read_frame(
    path: PathArg, kinds: Mapping[str, str], required: Sequence[str], schema: str
) -> Frame:
    """Read the columns of ``kinds`` (name -> INT/FLOAT/TIME) that ``path`` has; the
    ``required`` ones must all be there. Columns the schema does not know are ignored."""
    src = Source(path)
    src.check_readable()
    names = _column_names(src)
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise src.error("appears twice in the header", column=name)
        seen.add(name)
    missing = [c for c in required if c not in seen]
    if missing:
        found = ", ".join(clip(repr(c)) for c in names[:20])
        if len(names) > 20:
            found += f", … ({len(names)} columns)"
        raise src.error(
            f"missing required column(s) {', '.join(repr(c) for c in missing)} "
            f"({schema} files need {', '.join(required)}; found {found})"
        )
    present = [c for c in kinds if c in seen]
    if src.format == "csv":
        arrow = {INT: pa.int64(), FLOAT: pa.float64(), TIME: pa.string()}
        types = {c: arrow[kinds[c]] for c in present}
        opts = pacsv.ConvertOptions(column_types=types, include_columns=present,
                                    null_values=[""], strings_can_be_null=True)
        try:
            with arrow_file(src.path) as fh:
                table = pacsv.read_csv(fh, convert_options=opts)
        except pa.ArrowInvalid as e:
            raise _csv_error(src, names, str(e)) from None
        except (pa.ArrowException, OSError) as e:
            raise src.error(f"cannot read CSV ({clip(str(e), 200)})") from None
    else:
        import pyarrow.parquet as pq

        try:
            with arrow_file(src.path) as fh:
                table = pq.read_table(fh, columns=present)
        except (pa.ArrowException, OSError) as e:
            raise src.error(f"not a readable Parquet file ({clip(str(e), 200)})") from None
    return Frame(src, table)


def _csv_error(src: Source, names: list[str], message: str) -> InputError:
    """Turn a pyarrow CSV error (which has no line number) into a located InputError."""
    if "invalid UTF8" in message or "\ufffd" in message:
        utf8 = _utf8_error(src, names)
        if utf8 is not None:
            return utf8
    if "straddling object" in message:
        return _long_line(src, names)
    m = _CONVERSION.search(message)
    if m and int(m[1]) < len(names):
        name, value = names[int(m[1])], m[3]
        integer = m[2].startswith(("int", "uint"))
        what = "an integer" if integer else "a number"
        opts = pacsv.ConvertOptions(
            include_columns=[name], column_types={name: pa.string()}, null_values=[]
        )
        with arrow_file(src.path) as fh:
            col = pacsv.read_csv(fh, convert_options=opts).column(0)
        row = pc.index(col, value).as_py()
        where = {"row": None if row < 0 else row, "column": name}
        if integer and re.fullmatch(r"\s*[+-]?\d+\s*", value):
            return src.error(f"value {clip(value.strip())} is out of range (expected "
                             f"{int_range(-MAX_INDEX, MAX_INDEX)})", **where)
        return src.error(f"value {clip(repr(value))} is not {what}", **where)
    m = _FIELD_COUNT.search(message)
    if m:
        line = src.line_with_field_count_not(int(m[1]))
        return src.error(f"expected {m[1]} comma-separated fields, found {m[2]}", line=line)
    return src.error(f"cannot parse CSV ({clip(message, 200)})")


def _long_line(src: Source, names: list[str]) -> InputError:
    """The first line longer than ``MAX_LINE_BYTES`` and its longest cell, found by
    streaming the file (it may be large; no line is held in memory)."""
    line, length, cell, cell_len, best = 1, 0, 0, 0, (0, 0)
    prev_cr = False
    with src.path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            start = 0
            for m in re.finditer(rb"[,\r\n]", block):
                n = m.start() - start
                length, cell_len, start = length + n + 1, cell_len + n, m.end()
                sep = m[0]
                if sep == b"\n" and prev_cr and n == 0:
                    prev_cr = False
                    length -= 1
                    continue
                prev_cr = sep == b"\r"
                best = max(best, (cell_len, -cell))
                if sep == b",":
                    cell, cell_len = cell + 1, 0
                    continue
                if length - 1 > MAX_LINE_BYTES:
                    return _line_too_long(src, names, line, length - 1, best)
                line, length, cell, cell_len, best = line + 1, 0, 0, 0, (0, 0)
            n = len(block) - start
            length, cell_len = length + n, cell_len + n
    best = max(best, (cell_len, -cell))
    return _line_too_long(src, names, line, length, best)


def _line_too_long(src: Source, names: list[str], line: int, length: int,
                   best: tuple[int, int]) -> InputError:
    size, i = best[0], -best[1]
    column = names[i] if i < len(names) else None
    return src.error(f"cell of {size} characters, on a line of {length} bytes: longer than "
                     f"the {MAX_LINE_BYTES} bytes a line may hold (expected a number)",
                     line=line, column=column)


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


def write_frame(path: PathArg, columns: Mapping[str, pa.Array], *,
                row_group_size: int | None = None) -> None:
    """Write ``columns`` (in order) to ``path`` as CSV or Parquet by its extension.

    CSV: a plain header line, then one line per row, numbers in shortest round-trip form,
    nulls as empty cells, nothing quoted. Parquet: row groups of at most
    ``row_group_size`` rows (default pyarrow's). Written atomically (:func:`atomic_path`)."""
    fmt = file_format(path)
    table = pa.table(dict(columns))
    try:
        with atomic_path(path, make_parent=False) as tmp:
            if fmt == "csv":
                with open(tmp, "wb") as fh:
                    fh.write((",".join(table.column_names) + "\n").encode())
                    opts = pacsv.WriteOptions(include_header=False, quoting_style="none")
                    pacsv.write_csv(table, fh, opts)
            else:
                import pyarrow.parquet as pq

                with arrow_file(tmp, "wb") as fh:
                    pq.write_table(table, fh, row_group_size=row_group_size)
    except OutputError as e:  # names the file already (disk full, permission, …)
        raise InputError(str(e), file=str(path)) from None


def int_array(values: np.ndarray, missing: np.ndarray | None = None) -> pa.Array:
    """int64 array for writing; ``missing`` rows become nulls (empty CSV cells)."""
    return from_numpy(values, pa.int64(), missing)


def float_array(values: np.ndarray, *, nan_as_null: bool = False) -> pa.Array:
    """float64 array for writing; with ``nan_as_null`` NaN becomes a null (empty CSV cell)."""
    v = np.asarray(values, np.float64)
    return from_numpy(v, pa.float64(), np.isnan(v) if nan_as_null else None)
