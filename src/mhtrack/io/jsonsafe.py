"""One JSON sanitiser for every JSON that mhtrack writes or hashes.

JSON (RFC 8259) has no NaN or infinity and no NumPy types; :func:`to_jsonable` maps
NumPy scalars and arrays to plain numbers and lists, tuples to lists, dict keys to
strings and (by default) non-finite floats to ``null``, so any JSON parser reads the
result. With ``strict=True`` an object that is not JSON data raises ``TypeError`` instead
of passing through (for hashing, where silently dropping a value would be wrong).
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np


def to_jsonable(obj: Any, *, nonfinite_as_null: bool = True, strict: bool = False) -> Any:
    """Plain JSON data from ``obj``: dicts (keys as ``str``), lists, ``str``, ``int``,
    ``float``, ``bool`` and ``None``; NaN/±inf become ``None`` unless
    ``nonfinite_as_null`` is false."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v, nonfinite_as_null=nonfinite_as_null, strict=strict)
                for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v, nonfinite_as_null=nonfinite_as_null, strict=strict)
                for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist(), nonfinite_as_null=nonfinite_as_null, strict=strict)
    if isinstance(obj, bool | np.bool_):
        return bool(obj)
    if isinstance(obj, int | np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        f = float(obj)
        return None if nonfinite_as_null and not math.isfinite(f) else f
    if obj is None or isinstance(obj, str):
        return obj
    if strict:
        raise TypeError(f"not JSON data: {type(obj).__name__}")
    return obj


def dumps(obj: Any, **kwargs: Any) -> str:
    """``json.dumps`` of :func:`to_jsonable` ``(obj)`` that refuses NaN (``allow_nan=False``),
    so the text is valid JSON; ``kwargs`` go to ``json.dumps`` (``indent``, ``sort_keys``)."""
    return json.dumps(to_jsonable(obj), allow_nan=False, **kwargs)
