"""Weighted 2-D moments up to order 4 about an anchor, the sufficient statistics of the
forgetting mixture (:mod:`mhtrack.clutter.forgetting`).

A component's statistics are ``M_pq = Σ_i w_i dx_i^p dy_i^q`` with ``d_i = z_i − a`` about
its anchor ``a``, for the 15 pairs ``p + q ≤ 4`` (:data:`POWERS`). Order ≤ 2 gives the
weight, mean and covariance; order 4 the kurtosis along an axis (the split test). Moving
the anchor by ``δ`` is the binomial expansion of ``(dx − δx)^p (dy − δy)^q``:

    M'_pq = Σ_{a≤p, b≤q} C(p,a) C(q,b) (−δx)^{p−a} (−δy)^{q−b} M_ab,

exact in exact arithmetic; the anchor is kept at the component's mean so that the sums
stay well conditioned far from the origin (a 250 km radar).
"""

from __future__ import annotations

from math import comb

import numpy as np

#: (p, q) of each column, by total order.
POWERS: tuple[tuple[int, int], ...] = tuple(
    (p, t - p) for t in range(5) for p in range(t, -1, -1))
_IDX = {pq: i for i, pq in enumerate(POWERS)}
N_MOMENTS = len(POWERS)
_UPTO = {o: sum(1 for p, q in POWERS if p + q <= o) for o in range(5)}
_P = np.array([p for p, _ in POWERS])
_Q = np.array([q for _, q in POWERS])
_TERMS = np.array([(_IDX[(p, q)], _IDX[(a, b)], comb(p, a) * comb(q, b), p - a, q - b)
                   for (p, q) in POWERS for a in range(p + 1) for b in range(q + 1)])
_TO_TARGET = np.eye(N_MOMENTS)[_TERMS[:, 0]]  # (terms, 15): each term's target column
I00, I10, I01, I20, I02, I11 = (_IDX[k] for k in ((0, 0), (1, 0), (0, 1), (2, 0), (0, 2),
                                                   (1, 1)))
_I4 = np.array([_IDX[(a, 4 - a)] for a in range(5)])
_C4 = np.array([comb(4, a) for a in range(5)], float)


def plot_moments(z: np.ndarray, anchors: np.ndarray, resp: np.ndarray,
                 order: int = 4) -> np.ndarray:
    """(K, 15) ``Σ_i r_ki dx^p dy^q`` of plots ``z`` (n, 2) about ``anchors`` (K, 2) with
    responsibilities ``resp`` (K, n), for ``p + q ≤ order`` (the other columns 0)."""
    k, n = resp.shape
    dx = z[None, :, 0] - anchors[:, 0, None]
    dy = z[None, :, 1] - anchors[:, 1, None]
    px, py = [np.ones((k, n)), dx], [np.ones((k, n)), dy]
    for _ in range(2, order + 1):
        px.append(px[-1] * dx)
        py.append(py[-1] * dy)
    out = np.zeros((k, N_MOMENTS))
    for i, (p, q) in enumerate(POWERS[:_UPTO[order]]):
        out[:, i] = np.einsum("kn,kn->k", resp, px[p] * py[q] if p and q else
                              px[p] if p else py[q])
    return out


def shift(m: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Moments ``m`` (K, 15) about anchors ``a`` re-expressed about ``a + delta`` (K, 2)."""
    _, s, c, ex, ey = _TERMS.T
    f = c * (-delta[:, None, 0]) ** ex * (-delta[:, None, 1]) ** ey * m[:, s]
    return f @ _TO_TARGET


def mean_cov(m: np.ndarray, anchors: np.ndarray, reg: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weights ``M_00`` (K,), means (K, 2) and covariances (K, 2, 2) (+ ``reg``·I) of
    moments about ``anchors``."""
    w = m[:, I00]
    d = m[:, I10:I01 + 1] / w[:, None]  # mean − anchor
    cov = np.empty((len(w), 2, 2))
    cov[:, 0, 0] = m[:, I20] / w - d[:, 0] * d[:, 0] + reg
    cov[:, 1, 1] = m[:, I02] / w - d[:, 1] * d[:, 1] + reg
    cov[:, 0, 1] = cov[:, 1, 0] = m[:, I11] / w - d[:, 0] * d[:, 1]
    return w, anchors + d, cov


def principal_kurtosis(m: np.ndarray, cov: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                 np.ndarray]:
    """Per component (moments about its mean): the unit principal axis ``v`` (K, 2), its
    variance ``λ₁`` and the kurtosis ``β₂ = E[(v·d)⁴] / λ₁²`` along it (3 for a Gaussian,
    1.8 for a uniform bar, below 2 for two well separated equal clumps)."""
    a, b, c = cov[:, 0, 0], cov[:, 0, 1], cov[:, 1, 1]
    lam = 0.5 * (a + c) + np.hypot(0.5 * (a - c), b)  # the larger eigenvalue, closed form
    v = np.where((np.abs(b) > 0)[:, None], np.column_stack([b, lam - a]),
                 np.where((a >= c)[:, None], [[1.0, 0.0]], [[0.0, 1.0]]))
    v = v / np.linalg.norm(v, axis=1, keepdims=True)
    a = np.arange(5)
    proj = _C4 * v[:, None, 0] ** a * v[:, None, 1] ** (4 - a)
    m4 = (proj * m[:, _I4]).sum(axis=1) / m[:, I00]
    return v, lam, m4 / lam**2


def gaussian_moments(w: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """(K, 15) moments about the mean of Gaussians of weight ``w`` (K,) and covariance
    ``cov`` (Isserlis: odd central moments 0, ``E[dx⁴] = 3σxx²``, ``E[dx²dy²] = σxxσyy +
    2σxy²``, ...)."""
    sxx, syy, sxy = cov[:, 0, 0], cov[:, 1, 1], cov[:, 0, 1]
    m = np.zeros((len(w), N_MOMENTS))
    m[:, I00] = 1.0
    m[:, I20], m[:, I02], m[:, I11] = sxx, syy, sxy
    m[:, _IDX[(4, 0)]] = 3 * sxx**2
    m[:, _IDX[(3, 1)]] = 3 * sxx * sxy
    m[:, _IDX[(2, 2)]] = sxx * syy + 2 * sxy**2
    m[:, _IDX[(1, 3)]] = 3 * syy * sxy
    m[:, _IDX[(0, 4)]] = 3 * syy**2
    return m * w[:, None]
