"""The bounds of the numbers mhtrack reads: one place for every reader and CLI option.

A number outside its bound is refused where it enters (a file reader, a TOML reader, a
command-line option) with one line naming the file, line and field (or the option) and
the range expected, e.g. ``plots.csv, line 3, column 'scan': 9007199254740993 is out of
range (expected an integer in [-2^53, 2^53])``. The table is in ``docs/errors.md``.

* Integers (scan and frame numbers, track, target and sensor ids, plot indices) are
  within ``±MAX_INDEX = 2^53``: every one of them is exact in a float64 too, so scan
  times ``k·T``, JSON output and NumPy arithmetic never round them.
* Floats are finite and within ``±MAX_MAGNITUDE = 1e15`` (squares and sums of squares stay
  far from overflow); times within ``±MAX_TIME_S``; rates and densities have their own
  bounds below. Tighter, domain bounds (coordinates within ±1e9 m,
  :data:`mhtrack.records.MAX_COORDINATE`; scenario limits in
  :mod:`mhtrack.scenario.limits`) apply on top.
* Seeds are integers in ``[0, MAX_SEED]`` (what NumPy's ``SeedSequence`` and the job
  hashes take without surprises).
* Table files: at most ``MAX_COLUMNS`` columns and ``MAX_LINE_BYTES`` per line; TOML and
  JSON files at most ``MAX_NESTING`` levels deep.
"""

from __future__ import annotations

import math

from mhtrack.errors import short_number

#: Largest |integer| read from a file or an option: 2^53 (exact in float64).
MAX_INDEX = 2**53
#: Largest |float| read from a file or an option.
MAX_MAGNITUDE = 1e15
#: Largest |time| in s (about 31 700 years: Unix times and scan times k·T fit).
MAX_TIME_S = 1e12
#: Largest seed (2^63 − 1).
MAX_SEED = 2**63 - 1
#: Largest clutter rate: mean plots per scan (per sensor).
MAX_RATE = 1e7
#: Largest spatial density (per m²): one plot per mm².
MAX_DENSITY = 1e6
#: Largest metric cut-off distance (m): 10 000 km.
MAX_CUTOFF = 1e7
#: Largest OSPA/GOSPA order p (cut-off^p stays finite: 1e7^20 = 1e140).
MAX_ORDER = 20.0
#: Largest number of columns in a table file's header.
MAX_COLUMNS = 10_000
#: Largest line of a CSV file, in bytes (pyarrow's block size; a cell longer than this
#: cannot be a number).
MAX_LINE_BYTES = 1 << 20
#: Deepest nesting of tables and arrays in a TOML or JSON file.
MAX_NESTING = 64
#: Largest state (.npz) file member once decompressed, in bytes.
MAX_STATE_MEMBER_BYTES = 1 << 30
#: Largest total of a state file's members once decompressed, in bytes.
MAX_STATE_BYTES = 2 << 30


def power_of_two(x: int) -> str:
    """``2^53`` for 2**53, ``2^63 - 1`` for 2**63 - 1, else the digits."""
    for e in range(1, 128):
        if x == 2**e:
            return f"2^{e}"
        if x == 2**e - 1:
            return f"2^{e} - 1"
    return str(x)


def show(x: float) -> str:
    """A bound as written in messages: ``2^53``, ``1e15``, ``0``."""
    if isinstance(x, int) and abs(x) >= 2**20:
        return ("-" if x < 0 else "") + power_of_two(abs(x))
    return short_number(x)


def int_range(lo: int, hi: int) -> str:
    """``an integer in [0, 2^53]``."""
    return f"an integer in [{show(lo)}, {show(hi)}]"


def float_range(lo: float, hi: float, *, lo_open: bool = False) -> str:
    """``a finite number in (0, 1e7]``."""
    return f"a finite number in {'(' if lo_open else '['}{show(lo)}, {show(hi)}]"


def int_problem(v: object, lo: int = -MAX_INDEX, hi: int = MAX_INDEX) -> str | None:
    """What is wrong with ``v`` as an integer in ``[lo, hi]``, or ``None``."""
    if isinstance(v, bool) or not isinstance(v, int):
        return f"expected {int_range(lo, hi)}, got {type(v).__name__} {clip(repr(v))}"
    if not lo <= v <= hi:
        return f"{clip(str(v))} is out of range (expected {int_range(lo, hi)})"
    return None


def float_problem(v: object, lo: float = -MAX_MAGNITUDE, hi: float = MAX_MAGNITUDE, *,
                  lo_open: bool = False) -> str | None:
    """What is wrong with ``v`` as a finite number in ``[lo, hi]`` (``(lo, hi]``), or
    ``None``."""
    expected = float_range(lo, hi, lo_open=lo_open)
    if isinstance(v, bool) or not isinstance(v, int | float):
        return f"expected {expected}, got {type(v).__name__} {clip(repr(v))}"
    try:
        x = float(v)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x) or x > hi or x < lo or (lo_open and x == lo):
        return f"{clip(repr(v))} is out of range (expected {expected})"
    return None


def clip(text: str, n: int = 40) -> str:
    """``text`` cut to ``n`` characters, saying how long it was."""
    if len(text) <= n:
        return text
    return f"{text[:n]}… ({len(text)} characters)"
