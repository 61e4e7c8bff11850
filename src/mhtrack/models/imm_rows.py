"""The IMM's predict and update row by row, compiled with numba when it is installed
(optional extra ``[fast]``): the same floats as :mod:`mhtrack.models.imm`'s NumPy path.

NumPy's element-wise operations are exact IEEE operations on each element, so a loop that
does, for each row, the same multiplications, divisions, additions and subtractions in the
same order gives the same floats bit for bit (numba's default, ``fastmath=False``: no
contraction into fused multiply-adds, no reassociation). The loops below follow
:func:`mhtrack.models.imm._mix_predict`, :func:`mhtrack.models.kalman.predict_cv`,
:func:`mhtrack.models.kalman.update_position` and :func:`mhtrack.models.imm.combine`
operation by operation (``tests/models/test_imm_rows.py`` checks bit equality on random
stores). What they save is the NumPy path's temporaries: a 2-model IMM's mixing makes
(M, 2, 2, 4, 4) arrays a step; a row here stays in registers and the L1 cache.

The compiled path is taken only for stores of at least :data:`MIN_ROWS` rows, so that
``mhtrack --help`` and small runs never import numba (~0.5 s) nor compile; the
environment variable ``MHTRACK_COMPILED=0`` turns it off. Compiled functions are cached
on disk (numba's ``cache=True``) beside this module when it is writable.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any

import numpy as np

from mhtrack.compiled import jit, numba_module

#: Rows (leaves, or gated pairs) from which the compiled loops are used.
MIN_ROWS = 4096

_KERNELS: dict[str, Callable[..., Any]] | None = None
_TRIED = False


def kernels(n_rows: int) -> dict[str, Callable[..., Any]] | None:
    """The compiled loops for a store of ``n_rows`` rows, or ``None`` (NumPy path): fewer
    rows than :data:`MIN_ROWS`, ``MHTRACK_COMPILED=0``, or numba not installed."""
    global _KERNELS, _TRIED
    if n_rows < MIN_ROWS:
        return None
    if not _TRIED:
        _TRIED = True
        _KERNELS = _compile()
    return _KERNELS


def _compile() -> dict[str, Callable[..., Any]] | None:
    """numba's ``njit`` of the loops below (``None``: numba absent or turned off,
    :func:`mhtrack.compiled.numba_module`)."""
    numba = numba_module()
    if numba is None:
        return None
    combine = jit(numba, _combine_row)
    out = {}
    for name, fn in (("predict", predict_rows), ("update", update_rows),
                     ("grow", grow_rows)):
        # the loop's own copy, whose global ``_combine_row`` is the compiled one
        glob = {**fn.__globals__, "_combine_row": combine}
        out[name] = jit(numba, types.FunctionType(fn.__code__, glob, fn.__name__))
    return out


def predict_rows(xm: np.ndarray, Pm: np.ndarray, mu: np.ndarray, mubar: np.ndarray,
                 pim: np.ndarray, dt: np.ndarray, Q: np.ndarray, x: np.ndarray,
                 P: np.ndarray, xp: np.ndarray, Pp: np.ndarray) -> None:
    """Mixing, each model's CV prediction and their moment-matched mixture, row by row:
    ``xm`` (M, r, 4), ``Pm`` (M, r, 4, 4), ``mu``, ``mubar`` (M, r); ``pim`` (1 or M,
    r, r), ``dt`` (1 or M,), ``Q`` (1 or M, r, 4, 4). Writes ``x`` (M, 4), ``P`` (M, 4,
    4), ``xp`` (M, r, 4), ``Pp`` (M, r, 4, 4). Plain Python (numba compiles it)."""
    M, r = mu.shape
    w = np.empty((r, r))
    x0 = np.empty((r, 4))
    d = np.empty((r, r, 4))
    wd = np.empty((r, r, 4))
    P0 = np.empty((4, 4))
    S = np.empty((4, 4))
    F = np.empty((4, 4))
    dc = np.empty((r, 4))
    for m in range(M):
        pm = m if pim.shape[0] > 1 else 0
        dm = dt[m] if dt.shape[0] > 1 else dt[0]
        qm = m if Q.shape[0] > 1 else 0
        for i in range(r):
            for j in range(r):
                v = mubar[m, j]
                den = v if (v >= 1e-300 or v != v) else 1e-300
                w[i, j] = pim[pm, i, j] * mu[m, i] / den
        for j in range(r):
            for c in range(4):
                s = w[0, j] * xm[m, 0, c]
                for i in range(1, r):
                    s = s + w[i, j] * xm[m, i, c]
                x0[j, c] = s
        for i in range(r):
            for j in range(r):
                for c in range(4):
                    d[i, j, c] = xm[m, i, c] - x0[j, c]
                    wd[i, j, c] = w[i, j] * d[i, j, c]
        for j in range(r):
            for a in range(4):
                for b in range(4):
                    s = w[0, j] * Pm[m, 0, a, b]
                    for i in range(1, r):
                        s = s + w[i, j] * Pm[m, i, a, b]
                    P0[a, b] = s
                    t = wd[0, j, a] * d[0, j, b]
                    for i in range(1, r):
                        t = t + wd[i, j, a] * d[i, j, b]
                    S[a, b] = t
            for a in range(4):
                for b in range(4):
                    P0[a, b] = P0[a, b] + S[a, b]
            # predict_cv: x⁻ = F x0; rows then columns P[pos] += dt·P[vel]; + Q; symmetrised
            xp[m, j, 0] = x0[j, 0] + dm * x0[j, 1]
            xp[m, j, 1] = x0[j, 1]
            xp[m, j, 2] = x0[j, 2] + dm * x0[j, 3]
            xp[m, j, 3] = x0[j, 3]
            for b in range(4):
                F[0, b] = P0[0, b] + dm * P0[1, b]
                F[1, b] = P0[1, b]
                F[2, b] = P0[2, b] + dm * P0[3, b]
                F[3, b] = P0[3, b]
            for a in range(4):
                F[a, 0] = F[a, 0] + dm * F[a, 1]
                F[a, 2] = F[a, 2] + dm * F[a, 3]
            for a in range(4):
                for b in range(4):
                    F[a, b] = F[a, b] + Q[qm, j, a, b]
            for a in range(4):
                for b in range(4):
                    Pp[m, j, a, b] = (F[a, b] + F[b, a]) * 0.5
        _combine_row(xp, Pp, mubar, m, x, P, dc, S)


def update_rows(xm: np.ndarray, Pm: np.ndarray, mu: np.ndarray, z: np.ndarray,
                R: np.ndarray, x: np.ndarray, P: np.ndarray, xn: np.ndarray,
                Pn: np.ndarray) -> None:
    """Each model's Kalman update with the row's plot and the mixture with the posterior
    model probabilities ``mu`` (K, r): ``xm`` (K, r, 4), ``Pm`` (K, r, 4, 4), ``z`` (K, 2),
    ``R`` (1 or K, 2, 2). Writes ``x`` (K, 4), ``P`` (K, 4, 4), ``xn`` (K, r, 4), ``Pn``
    (K, r, 4, 4). Plain Python (numba compiles it)."""
    K, r = mu.shape
    k0 = np.empty(4)
    k1 = np.empty(4)
    T = np.empty((4, 4))
    dc = np.empty((r, 4))
    S = np.empty((4, 4))
    for k in range(K):
        rk = k if R.shape[0] > 1 else 0
        for j in range(r):
            s00 = Pm[k, j, 0, 0] + R[rk, 0, 0]
            s01 = Pm[k, j, 2, 0] + R[rk, 0, 1]
            s11 = Pm[k, j, 2, 2] + R[rk, 1, 1]
            det = s00 * s11 - s01 * s01
            i00 = s11 / det
            i01 = -s01 / det
            i11 = s00 / det
            for a in range(4):
                k0[a] = Pm[k, j, a, 0] * i00 + Pm[k, j, a, 2] * i01
                k1[a] = Pm[k, j, a, 0] * i01 + Pm[k, j, a, 2] * i11
            nu0 = z[k, 0] - xm[k, j, 0]
            nu1 = z[k, 1] - xm[k, j, 2]
            for a in range(4):
                xn[k, j, a] = xm[k, j, a] + k0[a] * nu0 + k1[a] * nu1
            for a in range(4):
                for b in range(4):
                    T[a, b] = Pm[k, j, a, b] - (k0[a] * Pm[k, j, b, 0]
                                                + k1[a] * Pm[k, j, b, 2])
            for a in range(4):
                for b in range(4):
                    Pn[k, j, a, b] = (T[a, b] + T[b, a]) * 0.5
        _combine_row(xn, Pn, mu, k, x, P, dc, S)


def grow_rows(x: np.ndarray, P: np.ndarray, xm: np.ndarray, Pm: np.ndarray,
              mu: np.ndarray, parent: np.ndarray, plot: np.ndarray, pair: np.ndarray,
              weight: np.ndarray, total: np.ndarray, z: np.ndarray, R: np.ndarray,
              cx: np.ndarray, cP: np.ndarray, cxm: np.ndarray, cPm: np.ndarray,
              cmu: np.ndarray) -> None:
    """The children's states in one pass: a miss (``plot < 0``) copies its ``parent``'s
    predicted row (``x, P, xm, Pm, mu``: the leaves' predictions), an update is
    :func:`update_rows` of the parent's prediction with plot ``z[plot]`` (``R`` (1 or n,
    2, 2) by plot) and the posterior model probabilities ``weight[pair] / total[pair]``
    (:class:`mhtrack.models.imm.Posterior`). Writes ``cx … cmu``, one row per child.
    Plain Python (numba compiles it)."""
    C = parent.shape[0]
    r = mu.shape[1]
    k0 = np.empty(4)
    k1 = np.empty(4)
    T = np.empty((4, 4))
    dc = np.empty((r, 4))
    S = np.empty((4, 4))
    for c in range(C):
        p = parent[c]
        j_plot = plot[c]
        if j_plot < 0:
            for a in range(4):
                cx[c, a] = x[p, a]
                for b in range(4):
                    cP[c, a, b] = P[p, a, b]
            for j in range(r):
                cmu[c, j] = mu[p, j]
                for a in range(4):
                    cxm[c, j, a] = xm[p, j, a]
                    for b in range(4):
                        cPm[c, j, a, b] = Pm[p, j, a, b]
            continue
        q = pair[c]
        rk = j_plot if R.shape[0] > 1 else 0
        for j in range(r):
            cmu[c, j] = weight[q, j] / total[q]
            s00 = Pm[p, j, 0, 0] + R[rk, 0, 0]
            s01 = Pm[p, j, 2, 0] + R[rk, 0, 1]
            s11 = Pm[p, j, 2, 2] + R[rk, 1, 1]
            det = s00 * s11 - s01 * s01
            i00 = s11 / det
            i01 = -s01 / det
            i11 = s00 / det
            for a in range(4):
                k0[a] = Pm[p, j, a, 0] * i00 + Pm[p, j, a, 2] * i01
                k1[a] = Pm[p, j, a, 0] * i01 + Pm[p, j, a, 2] * i11
            nu0 = z[j_plot, 0] - xm[p, j, 0]
            nu1 = z[j_plot, 1] - xm[p, j, 2]
            for a in range(4):
                cxm[c, j, a] = xm[p, j, a] + k0[a] * nu0 + k1[a] * nu1
            for a in range(4):
                for b in range(4):
                    T[a, b] = Pm[p, j, a, b] - (k0[a] * Pm[p, j, b, 0]
                                                + k1[a] * Pm[p, j, b, 2])
            for a in range(4):
                for b in range(4):
                    cPm[c, j, a, b] = (T[a, b] + T[b, a]) * 0.5
        _combine_row(cxm, cPm, cmu, c, cx, cP, dc, S)


def _combine_row(xm: np.ndarray, Pm: np.ndarray, mu: np.ndarray, m: int, x: np.ndarray,
                 P: np.ndarray, d: np.ndarray, S: np.ndarray) -> None:
    """:func:`mhtrack.models.imm.combine` of row ``m`` into ``x[m]``, ``P[m]`` (``d``,
    ``S``: scratch)."""
    r = mu.shape[1]
    for c in range(4):
        s = mu[m, 0] * xm[m, 0, c]
        for i in range(1, r):
            s = s + mu[m, i] * xm[m, i, c]
        x[m, c] = s
    for i in range(r):
        for c in range(4):
            d[i, c] = xm[m, i, c] - x[m, c]
    for a in range(4):
        for b in range(4):
            s = mu[m, 0] * Pm[m, 0, a, b]
            for i in range(1, r):
                s = s + mu[m, i] * Pm[m, i, a, b]
            t = (mu[m, 0] * d[0, a]) * d[0, b]
            for i in range(1, r):
                t = t + (mu[m, i] * d[i, a]) * d[i, b]
            S[a, b] = s + t
    for a in range(4):
        for b in range(4):
            P[m, a, b] = (S[a, b] + S[b, a]) * 0.5
