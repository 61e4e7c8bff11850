"""Kalman filtering of many constant-velocity tracks at once, element-wise.

Tracks are stacked: means ``x`` (M, 4) with state ``[x, vx, y, vy]`` and covariances
``P`` (M, 4, 4). Plots are positions ``z`` with either one shared covariance ``R`` (2, 2)
or one per pair (M, 2, 2). No Python loop runs over tracks; the 2×2 innovation covariance
is inverted in closed form (:mod:`mhtrack.models.linalg2`).

Equations (standard Kalman filter, e.g. Bar-Shalom et al. 2001 §5.2.3; P1 eqs. 1–2)::

    predict   x⁻ = F x,  P⁻ = F P Fᵀ + Q          F(dt) = I + dt·E (E adds velocity to position)
    innovate  ν = z − H x⁻,  S = H P⁻ Hᵀ + R
    update    K = P⁻ Hᵀ S⁻¹,  x = x⁻ + K ν,  P = P⁻ − K (P⁻ Hᵀ)ᵀ   (symmetrised)

Gating and the innovation log-likelihood are the MHT's (:mod:`mhtrack.mht.gating`); the
general matrix forms these specialise live in ``tests/reference/kalman_reference.py``.
"""

from __future__ import annotations

import numpy as np

from mhtrack.models.linalg2 import sym_det2


def symmetrised(P: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``0.5 (P + Pᵀ)`` over the last two axes, written into ``out`` (an array other than
    ``P``) when given: the same floats as the expression, one array instead of two."""
    out = np.add(P, P.swapaxes(-1, -2), out=out)  # the method: no wrapper set-up
    out *= 0.5
    return out


def predict_cv(
    x: np.ndarray, P: np.ndarray, dt: float | np.ndarray, Q: np.ndarray,
    overwrite: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Prediction with the constant-velocity ``F(dt) = I + dt·E``: ``x⁻ = F x``,
    ``P⁻ = F P Fᵀ + Q`` done as two row/column updates ``P[pos] += dt·P[vel]`` on the
    whole stack. ``dt`` is one interval, or one per row (M,) with ``Q`` (M, 4, 4)
    (asynchronous plots: each track to its own plot's time). Leading axes beyond the
    first are allowed (``x`` (M, …, 4), ``P`` (M, …, 4, 4), ``Q`` broadcasting to ``P``:
    the IMM's models at once). ``overwrite``: ``P`` is a scratch array of the caller's and
    is worked on in place (no copy; the result is the same)."""
    xp = x.copy()
    Pp = P if overwrite else P.copy()
    if np.ndim(dt) == 0:
        xp[..., 0::2] += dt * x[..., 1::2]
        Pp[..., 0::2, :] += dt * Pp[..., 1::2, :]
        Pp[..., :, 0::2] += dt * Pp[..., :, 1::2]
    else:
        d = np.asarray(dt, float).reshape((-1,) + (1,) * (x.ndim - 1))
        xp[..., 0::2] += d * x[..., 1::2]
        Pp[..., 0::2, :] += d[..., None] * Pp[..., 1::2, :]
        Pp[..., :, 0::2] += d[..., None] * Pp[..., :, 1::2]
    Pp += Q
    return xp, symmetrised(Pp)


def update_position(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Update of stacked pairs with position plots, element-wise: with ``A = P Hᵀ`` (two
    columns of ``P``), ``K = A S⁻¹``, ``x⁺ = x + K ν``, ``P⁺ = P − K Aᵀ`` (standard form,
    symmetrised; the Joseph form differs by rounding only). ``R`` is (2, 2) shared or
    (K, 2, 2) per pair."""
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R = np.asarray(R, float)
    a0, a1 = P[:, :, 0], P[:, :, 2]  # columns of P Hᵀ, (K, 4)
    s00 = a0[:, 0] + R[..., 0, 0]
    s01 = a0[:, 2] + R[..., 0, 1]
    s11 = a1[:, 2] + R[..., 1, 1]
    det = sym_det2(s00, s01, s11)
    i00, i01, i11 = s11 / det, -s01 / det, s00 / det
    k0 = a0 * i00[:, None] + a1 * i01[:, None]  # columns of K, (K, 4)
    k1 = a0 * i01[:, None] + a1 * i11[:, None]
    nu = z - x[:, 0::2]
    xn = x + k0 * nu[:, :1] + k1 * nu[:, 1:]
    # P − (k0 a0ᵀ + k1 a1ᵀ), in two arrays (the same operations, in the same order)
    Pn = np.multiply(k0[:, :, None], a0[:, None, :])
    tmp = np.multiply(k1[:, :, None], a1[:, None, :])
    Pn += tmp
    np.subtract(P, Pn, out=Pn)
    return xn, symmetrised(Pn, out=tmp)
