"""The ``time`` column of a timed plots file: seconds, ISO-8601 text, or a Parquet timestamp,
converted to float seconds.

* **Numbers** (CSV or Parquet numeric column) are seconds as written, on the user's own
  time scale (e.g. since the start of a recording).
* **ISO-8601 text** (``2024-05-01T12:00:03.250Z``, ``2024-05-01T13:00:03.25+01:00``; up to
  nanoseconds) and **Parquet timestamp** columns become **POSIX seconds**: seconds since
  1970-01-01T00:00:00Z, leap seconds not counted (the POSIX/Unix convention, which
  ``datetime.timestamp`` and NumPy's ``datetime64`` share). Text must carry its zone —
  ``Z`` or ``±hh:mm`` — so that no local time is guessed; a timestamp column without a
  time zone is taken as UTC (Arrow's convention for naive timestamps).

**Written back** (:func:`time_column`): tracks made from plots with ISO-8601 or timestamp
times keep them — ISO-8601 UTC text with nanoseconds in CSV
(``2024-05-01T12:00:03.250000000Z``), a ``timestamp[ns, UTC]`` column in Parquet —
and numeric times stay numbers, written as before. The nanoseconds are
``round(frac · 10⁹)`` of the seconds' fraction, so a float read back is the same float.

A float64 near 1.7·10⁹ s resolves 2.4·10⁻⁷ s, far below any radar's timing. The text is
parsed by Arrow's ISO-8601 parser (``pyarrow.compute.cast`` to ``timestamp[ns, UTC]``);
whole seconds and the nanoseconds are combined as ``s + ns / 10⁹`` (one rounding).
"""

from __future__ import annotations

from collections.abc import Callable
from datetime import datetime

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from mhtrack.io._frame import Frame

#: An example ISO-8601 time, shown in error messages.
ISO_EXAMPLE = "2024-05-01T12:00:03.250Z"
_NS = pa.timestamp("ns", tz="UTC")


def _first_failure(values: pa.Array, convert: Callable[[pa.Array], object]) -> int:
    """Index of the first element that ``convert`` refuses (bisection over slices: a few
    dozen conversions instead of one per row); ``values`` as a whole is known to fail."""
    lo, hi = 0, len(values)  # the first failure is in [lo, hi)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        try:
            convert(values.slice(lo, mid - lo))
        except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
            hi = mid
        else:
            lo = mid
    return lo


def posix_seconds(ns: np.ndarray) -> np.ndarray:
    """Float seconds of int64 nanoseconds since the POSIX epoch: ``s + r / 10⁹`` with
    ``s, r = divmod(ns, 10⁹)`` (the whole seconds are exact in float64)."""
    whole, rest = np.divmod(np.asarray(ns, np.int64), 10**9)
    return whole.astype(np.float64) + rest.astype(np.float64) / 1e9


def seconds(f: Frame, name: str = "time") -> np.ndarray:
    """Column ``name`` of ``f`` as float seconds (module docstring); missing or unparseable
    values raise a located :class:`~mhtrack.errors.InputError`."""
    col = f.table.column(name)
    if pa.types.is_timestamp(col.type):
        f.check(f.nulls(name), name, lambda r: "value is missing")
        ns = col.cast(pa.timestamp("ns", tz=col.type.tz)).combine_chunks()
        return posix_seconds(ns.view(pa.int64()).to_numpy(zero_copy_only=False))
    if not pa.types.is_string(col.type) and not pa.types.is_large_string(col.type):
        return f.floats(name)
    f.check(f.nulls(name), name, lambda r: "value is missing")
    text = col.combine_chunks()
    if text.null_count == 0 and len(text) == 0:
        return np.zeros(0)
    if _is_number(text[0].as_py()):
        return _numbers(f, name, text)
    try:
        ns = pc.cast(text, _NS)
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
        ns = None
    if ns is None:
        r = _first_failure(text, lambda a: pc.cast(a, _NS))
        f.fail(_bad_iso(text[r].as_py()), row=r, column=name)
    return posix_seconds(ns.view(pa.int64()).to_numpy(zero_copy_only=False))


def is_iso(f: Frame, name: str = "time") -> bool:
    """Whether column ``name`` of ``f`` holds times as ISO-8601 text or timestamps (not
    numbers of seconds)."""
    col = f.table.column(name)
    if pa.types.is_timestamp(col.type):
        return True
    if not (pa.types.is_string(col.type) or pa.types.is_large_string(col.type)):
        return False
    first = next((v for v in col.to_pylist()[:1] if v is not None), None)
    return first is not None and not _is_number(first)


def time_column(seconds_: np.ndarray, iso: bool, fmt: str) -> pa.Array:
    """Times to write: float seconds, or (``iso``) POSIX seconds as ISO-8601 UTC text
    (``fmt`` ``"csv"``) or a ``timestamp[ns, UTC]`` column (Parquet)."""
    v = np.asarray(seconds_, np.float64)
    if not iso:
        return pa.array(v, pa.float64())
    whole = np.floor(v)
    ns = whole.astype(np.int64) * 10**9 + np.rint((v - whole) * 1e9).astype(np.int64)
    stamps = pa.array(ns, pa.int64()).cast(_NS)
    return pc.strftime(stamps, format="%Y-%m-%dT%H:%M:%SZ") if fmt == "csv" else stamps


def _is_number(value: str) -> bool:
    try:
        float(value)
    except ValueError:
        return False
    return True


def _numbers(f: Frame, name: str, text: pa.Array) -> np.ndarray:
    """A text column whose first value is a number: all must be (seconds)."""
    try:
        v = pc.cast(text, pa.float64()).to_numpy(zero_copy_only=False)
    except pa.ArrowInvalid:
        v = None
    if v is None:
        r = _first_failure(text, lambda a: pc.cast(a, pa.float64()))
        f.fail(f"value {text[r].as_py()!r} is not a number (the first row's time "
               f"{text[0].as_py()!r} is seconds, so every row's must be)", row=r, column=name)
    f.check(~np.isfinite(v), name, lambda r: f"value {text[r].as_py()!r} is not finite")
    return f.bounded(name, np.ascontiguousarray(v, np.float64))


def _bad_iso(value: str) -> str:
    """Why ``value`` is not an ISO-8601 time with a zone."""
    try:
        parsed = datetime.fromisoformat(value)
    except ValueError:
        parsed = None
    if parsed is not None and parsed.tzinfo is None:
        return (f"time {value!r} has no time zone; end it with Z (UTC) or an offset such "
                "as +01:00")
    return (f"value {value!r} is neither a number of seconds nor an ISO-8601 time of the "
            f"form {ISO_EXAMPLE} (or with an offset such as +01:00)")
