"""Validation helpers for the dict form of a scenario: every error names its key path.

Messages read ``<path>: <what is wrong>``, e.g. ``targets[2].birth: must be <= death``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

import numpy as np

from mhtrack.bounds import MAX_INDEX, MAX_MAGNITUDE, clip
from mhtrack.errors import short_number as fmt

_KEYED = re.compile(r"^[A-Za-z_]\w*(\[\d+\])*(\.\w+(\[\d+\])*)*: ")


def join(path: str, key: str | int) -> str:
    """``join("targets", 2) == "targets[2]"``, ``join("targets[2]", "id") == "targets[2].id"``."""
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


@contextmanager
def at(path: str) -> Iterator[None]:
    """Prefix the message of a ``ValueError`` raised inside with ``path``, unless the message
    already starts with it (errors from model constructors carry no path of their own)."""
    try:
        yield
    except ValueError as e:
        msg = str(e)
        if any(msg.startswith(path + c) for c in ".:["):
            raise
        sep = "." if _KEYED.match(msg) else ": "
        raise ValueError(f"{path}{sep}{msg}") from None


def table(d: object, path: str) -> Mapping[str, Any]:
    if not isinstance(d, Mapping):
        raise ValueError(f"{path or 'scenario'}: expected a table (dict), got {_tname(d)}")
    return d


def keys(
    d: Mapping[str, Any], path: str, required: set[str], optional: set[str] = frozenset()
) -> None:
    """Reject unknown keys (by name) and report the first missing required key."""
    allowed = required | optional
    unknown = sorted(str(k) for k in d if k not in allowed)
    if unknown:
        names = ", ".join(repr(k) for k in unknown)
        where = path or "scenario"
        raise ValueError(
            f"{where}: unknown key{'s' if len(unknown) > 1 else ''} {names} "
            f"(allowed: {', '.join(sorted(allowed))})"
        )
    for k in sorted(required):
        if k not in d:
            raise ValueError(f"{join(path, k)}: missing")


def _tname(v: object) -> str:
    return {dict: "table", list: "array"}.get(type(v), type(v).__name__)


def _show(v: object) -> str:
    return clip(repr(v))


def number(
    v: object,
    path: str,
    *,
    lo: float | None = None,
    lo_open: bool = False,
    hi: float | None = None,
    unit: str = "",
    magnitude: bool = True,
) -> float:
    """A finite real number (bools rejected), optionally ``>= lo`` (or ``> lo``) and
    ``<= hi`` (``unit`` is appended to ``hi`` in the message); with ``magnitude``, also
    within ±:data:`mhtrack.bounds.MAX_MAGNITUDE`."""
    if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
        raise ValueError(f"{path}: expected a number, got {_tname(v)} {_show(v)}")
    try:
        x = float(v)
    except OverflowError:  # a Python int beyond the float range
        x = math.inf if v > 0 else -math.inf  # type: ignore[operator]
    if not math.isfinite(x):
        raise ValueError(f"{path}: must be finite, got {x}")
    if lo is not None and (x <= lo if lo_open else x < lo):
        raise ValueError(f"{path}: must be {'>' if lo_open else '>='} {lo}, got {x}")
    if hi is not None and x > hi:
        raise ValueError(f"{path}: must be <= {fmt(hi)}{' ' + unit if unit else ''}, got {x}")
    if magnitude and abs(x) > MAX_MAGNITUDE:
        raise ValueError(f"{path}: must be within ±{fmt(MAX_MAGNITUDE)} (mhtrack.bounds), "
                         f"got {x}")
    return x


def bounded(v: object, path: str, limit: float, unit: str = "m") -> float:
    """A finite number with ``|v| <= limit`` (coordinates, velocities)."""
    x = number(v, path, magnitude=False)
    if abs(x) > limit:
        raise ValueError(f"{path}: must be within ±{fmt(limit)} {unit}, got {x}")
    return x


def probability(v: object, path: str) -> float:
    x = number(v, path)
    if not 0.0 <= x <= 1.0:
        raise ValueError(f"{path}: must be in [0, 1], got {x}")
    return x


def detection_probability(v: object, path: str) -> float:
    """A sensor's ``P_D`` in (0, 1] — the one rule of scenario files, sensors files,
    overrides and the CLI's ``--pd``: a sensor that never detects gives nothing to track."""
    x = number(v, path)
    if not 0.0 < x <= 1.0:
        raise ValueError(f"{path}: must be in (0, 1], got {x} (detection probability; a "
                         "sensor with P_D = 0 never detects, so nothing could be tracked)")
    return x


def integer(v: object, path: str, *, lo: int | None = None,
            hi: int | None = MAX_INDEX) -> int:
    """An integer (bools and floats rejected), optionally ``>= lo``, and within
    ``[-2^53, hi]`` (default ``hi = 2^53``, :data:`mhtrack.bounds.MAX_INDEX`; ``None``:
    the caller checks the range)."""
    if isinstance(v, bool) or not isinstance(v, int | np.integer):
        raise ValueError(f"{path}: expected an integer, got {_tname(v)} {_show(v)}")
    if lo is not None and int(v) < lo:
        raise ValueError(f"{path}: must be >= {lo}, got {clip(str(int(v)))}")
    if hi is not None and (int(v) > hi or int(v) < -MAX_INDEX):
        raise ValueError(f"{path}: must be an integer in [{lo if lo is not None else -MAX_INDEX}"
                         f", {hi}], got {clip(str(int(v)))}")
    return int(v)


def string(v: object, path: str) -> str:
    if not isinstance(v, str):
        raise ValueError(f"{path}: expected a string, got {_tname(v)} {_show(v)}")
    return v


def array(
    v: object, path: str, shape: tuple[int | None, ...], limit: float | None = None,
    *, magnitude: bool = True,
) -> np.ndarray:
    """A nested list of finite numbers of the given ``shape`` (``None`` = any length), each
    within ``±limit`` if given (in m); the error names the first offending element, e.g.
    ``means[1][0]``."""
    if len(shape) == 0:
        return np.asarray(number(v, path, magnitude=magnitude) if limit is None
                          else bounded(v, path, limit))
    if not isinstance(v, list | tuple | np.ndarray):
        raise ValueError(f"{path}: expected a list, got {_tname(v)} {_show(v)}")
    n = shape[0]
    if n is not None and len(v) != n:
        raise ValueError(f"{path}: expected {n} elements, got {len(v)}")
    rows = [array(e, join(path, i), shape[1:], limit, magnitude=magnitude)
            for i, e in enumerate(v)]
    if not rows:
        return np.zeros((0, *[s or 0 for s in shape[1:]]))
    return np.stack(rows)


def close(a: object, b: object, rel: float = 1e-12) -> bool:
    """Structural equality of plain nested dicts/lists, floats equal to ``rel`` relative."""
    if isinstance(a, Mapping) and isinstance(b, Mapping):
        return a.keys() == b.keys() and all(close(a[k], b[k], rel) for k in a)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(close(x, y, rel) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) or isinstance(b, float):
        if isinstance(a, bool) or isinstance(b, bool):
            return False
        return a == b or abs(a - b) <= rel * max(abs(a), abs(b))  # type: ignore[operator]
    return type(a) is type(b) and a == b
