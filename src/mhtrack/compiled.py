"""numba, for the loops kept compiled (optional extra ``[fast]``), in one place: whether
it may be used and its ``njit`` with the on-disk cache.

Every compiled loop in mhtrack does, element by element, the NumPy path's own
multiplications, divisions, additions and subtractions in the same order, so it gives the
same floats bit for bit (numba's default, ``fastmath=False``: no contraction into fused
multiply-adds, no reassociation); transcendental functions stay with NumPy. Switching a
loop on or off therefore never changes a result, only the time.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any


def numba_module() -> Any | None:
    """The ``numba`` module, or ``None``: not installed, or the environment variable
    ``MHTRACK_COMPILED=0`` turns compiled loops off."""
    if os.environ.get("MHTRACK_COMPILED", "1") == "0":
        return None
    try:
        import numba
    except ImportError:
        return None
    return numba


def jit(numba: Any, fn: Callable[..., Any]) -> Callable[..., Any]:
    """``numba.njit`` with NumPy's error model (a division by zero gives ``inf`` or
    ``nan``, as NumPy's does, instead of raising ``ZeroDivisionError``) and the on-disk
    cache (beside the module when it is writable), or without the cache where it cannot be
    written."""
    try:
        return numba.njit(cache=True, nogil=True, error_model="numpy")(fn)
    except RuntimeError:  # numba: "cannot cache function …: no locator available"
        return numba.njit(nogil=True, error_model="numpy")(fn)
