"""NumPy idioms kept only for speed, in one place. Each gives bit for bit what the plain
form in its docstring gives, and says what it saves, measured on ``crossing`` with
MHT-AGMM (90 scans, ~1.3 ms a scan; ``benchmarks/profile_crossing.py``, ``timeit`` on the
sizes of a scan, median of 7). Where a trick saved less than 1 % of a scan the plain form
is used instead, in the module that needs it (``docs/performance.md``, *Speed idioms*).
"""

from __future__ import annotations

import numpy as np


def changes(sorted_keys: np.ndarray) -> np.ndarray:
    """Mask over the rows of ``sorted_keys``: the row starts a run of equal values (the
    first row always); ``np.r_[True, k[1:] != k[:-1]]``.

    Saves ~2 µs a call (1.0 against 3.0 µs on 50 keys: no index-trick set-up); ~14 calls
    a scan, ~2 % of it."""
    flag = np.empty(sorted_keys.size, bool)
    flag[:1] = True
    np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=flag[1:])
    return flag


def same_floats(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether ``a`` and ``b`` hold the same floats bit for bit, in the same shape (the
    key of a one-scan cache: ``-0.0`` and ``0.0`` differ, a NaN equals itself).

    A byte comparison: ~1 µs on a scan's plots; the cache it keys
    (:meth:`mhtrack.clutter.mixture.MixtureClutter.intensity`) saves a density evaluation
    of every plot of the scan."""
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()
