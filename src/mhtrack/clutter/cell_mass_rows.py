"""The cell-mass quadrature's (:mod:`mhtrack.clutter.cell_mass`) segments and node
products as loops, compiled with numba when it is installed (optional extra ``[fast]``):
the same floats as the NumPy path, bit for bit (:mod:`mhtrack.compiled`).

:func:`segment_rows` follows ``cell_mass._batch_segments`` and :func:`product_rows` the
node products of ``cell_mass._gauss_mass`` operation by operation: NumPy's ``maximum``,
``minimum`` and ``clip`` with their own NaN and tie rules, the cuts in the same order,
each product in the same association; the exponential, sines and cosines stay with NumPy.
``tests/clutter/test_cell_mass_rows.py`` checks bit equality against the NumPy path on
random mixtures in the plane and in range and bearing. What they save is NumPy's cost per
call: the NumPy path makes ~60 calls on arrays of a few hundred nodes
(``benchmarks/bench_clutter_map.py``).

A run takes the compiled loops after :data:`MIN_CALLS` quadratures (numba's import and
loading the loops cost more than a short run's quadratures), or at once after
:func:`load` (:func:`mhtrack.pipeline.preload.preload`, the benchmark); results never
depend on which path ran.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from mhtrack.compiled import jit, numba_module

#: Quadratures from which a run loads and uses the compiled loops.
MIN_CALLS = 10_000

_COMPILED: dict[str, Callable[..., Any]] = {}  # numba's functions, once made
_PATH: dict[str, Any] = {"kernels": None, "decided": False, "calls": 0}


def kernels() -> dict[str, Callable[..., Any]] | None:
    """The compiled loops, or ``None`` (NumPy path): before :data:`MIN_CALLS` calls
    unless loaded, numba absent, or ``MHTRACK_COMPILED=0``."""
    if not _PATH["decided"]:
        _PATH["calls"] += 1
        if _PATH["calls"] < MIN_CALLS:
            return None
        load()
    return _PATH["kernels"]


def load() -> bool:
    """Make numba's functions of the loops now (each compiles, or loads from numba's cache,
    at its first call: :func:`mhtrack.clutter.cell_mass.preload` makes those calls);
    whether they are in use."""
    if not _PATH["decided"]:
        _PATH["decided"] = True
        numba = numba_module()
        if numba is not None and not _COMPILED:
            _COMPILED.update(segments=jit(numba, segment_rows),
                             products=jit(numba, product_rows))
        _PATH["kernels"] = _COMPILED if numba is not None else None
    return _PATH["kernels"] is not None


def use(compiled: bool) -> bool:
    """From now on the compiled loops (loaded now, where numba is there) or the NumPy
    path, whatever the count of calls (the benchmark's two paths, the tests); whether the
    compiled loops are in use."""
    _PATH["decided"], _PATH["kernels"] = False, None
    if compiled:
        return load()
    _PATH["decided"] = True
    return False


def segment_rows(lo: np.ndarray, hi: np.ndarray, step: np.ndarray, extra: np.ndarray,
                 unit: np.ndarray, xq: np.ndarray, wq: np.ndarray, max_steps: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """``cell_mass._batch_segments(lo, hi, step, extra)`` (its ``MAX_STEPS``, Gauss–Legendre
    nodes ``xq`` and weights ``wq`` given) with its nodes and weights times ``unit`` (per
    row): (R, P) nodes, weights, cell index, and ``False`` (nothing
    computed) when a bound is not finite. Plain Python (numba compiles it)."""
    R, nq = lo.shape[0], xq.shape[0]
    his, steps, firsts = np.empty(R), np.empty(R), np.empty(R)
    top_edge, top_step = -np.inf, -np.inf
    for i in range(R):
        lo_i, h = lo[i], hi[i]
        if not (np.isfinite(lo_i) and np.isfinite(h)):
            return np.empty((R, 0)), np.empty((R, 0)), np.empty((R, 0), np.int64), False
        h = h if h >= lo_i else lo_i  # np.maximum(hi, lo)
        s, t = step[i], (h - lo_i) / max_steps
        s = s if (s >= t or s != s) else t  # np.maximum
        if not s < 1.0:
            d = h - lo_i
            s = d if (d >= 1e-300 or d != d) else 1e-300
        first = np.floor(lo_i) + 1.0
        e, k = np.ceil(h) - first, np.ceil((h - lo_i) / s)
        if not (np.isfinite(e) and np.isfinite(k)):
            return np.empty((R, 0)), np.empty((R, 0)), np.empty((R, 0), np.int64), False
        top_edge, top_step = max(top_edge, e), max(top_step, k)
        his[i], steps[i], firsts[i] = h, s, first
    n_edge, n_step = max(0, int(top_edge)), max(1, int(top_step))
    C = 3 + n_edge + n_step - 1
    x, w = np.empty((R, (C - 1) * nq)), np.empty((R, (C - 1) * nq))
    idx = np.empty((R, (C - 1) * nq), np.int64)
    b = np.empty(C)
    for i in range(R):
        lo_i, h, s = lo[i], his[i], steps[i]
        b[0], b[1], b[2] = lo_i, h, extra[i]
        for k in range(n_edge):
            b[3 + k] = firsts[i] + k
        for k in range(1, n_step):
            b[2 + n_edge + k] = lo_i + k * s
        for c in range(C):  # np.clip: NaN kept, else max(·, lo) then min(·, hi)
            v = b[c]
            if v == v:
                v = v if v > lo_i else lo_i
                v = v if v < h else h
            b[c] = v
        b.sort()
        for c in range(C - 1):
            half, mid = 0.5 * (b[c + 1] - b[c]), 0.5 * (b[c + 1] + b[c])
            cell = np.int64(np.floor(mid))
            for q in range(nq):
                x[i, c * nq + q] = (mid + half * xq[q]) * unit[i]
                w[i, c * nq + q] = (half * wq[q]) * unit[i]
                idx[i, c * nq + q] = cell
    return x, w, idx, True


def product_rows(rr: np.ndarray, wr: np.ndarray, ir: np.ndarray, ta: np.ndarray,
                 tb: np.ndarray, wt: np.ndarray, it: np.ndarray, polar: bool, r0: float,
                 rmin: float, site0: float, site1: float, weights: np.ndarray,
                 means: np.ndarray, cov: np.ndarray, det: np.ndarray, n_rings: int,
                 n_azimuth: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each Gaussian's range nodes (in the map) times its bearing nodes, in
    ``cell_mass._gauss_mass``'s order: the exponent ``−q/2``, the factor
    ``π_j / (2π √det_j) · w_r · w_θ`` and the flat cell of every product. ``ta``, ``tb``:
    the bearing nodes' sines and cosines (plane), or ``ta`` their ``s`` (polar). Plain
    Python (numba compiles it)."""
    n, n_r, n_t = rr.shape[0], rr.shape[1], ta.shape[1]
    size = n * n_r * n_t
    arg, coef, flat = np.empty(size), np.empty(size), np.empty(size, np.int64)
    m = 0
    for j in range(n):
        c00, c01, c11 = cov[j, 0, 0] / det[j], cov[j, 0, 1] / det[j], cov[j, 1, 1] / det[j]
        a = weights[j] / (2.0 * np.pi * np.sqrt(det[j]))
        for p in range(n_r):
            if not (wr[j, p] > 0 and ir[j, p] < n_rings):
                continue
            r = rr[j, p]
            w_r = wr[j, p] * r
            if polar:
                floor_r = r if (r >= rmin or r != r) else rmin  # np.maximum(rr, rmin)
                w_r = w_r * (r0 / floor_r)
            for q in range(n_t):
                if not wt[j, q] > 0:
                    continue
                if polar:
                    dx, dy = r - means[j, 0], ta[j, q] - means[j, 1]
                else:
                    dx = r * ta[j, q] + (site0 - means[j, 0])
                    dy = r * tb[j, q] + (site1 - means[j, 1])
                arg[m] = -0.5 * (c11 * dx * dx - 2.0 * c01 * dx * dy + c00 * dy * dy)
                coef[m] = a * w_r * wt[j, q]
                flat[m] = ir[j, p] * n_azimuth + it[j, q] % n_azimuth
                m += 1
    return arg[:m], coef[:m], flat[:m]
