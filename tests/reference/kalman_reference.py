"""Reference Kalman filter and gate in general matrix form, for tests only.

The library's hot path (:mod:`mhtrack.models.kalman`, :mod:`mhtrack.mht.gating`) is
specialised to the constant-velocity state and position plots and computed element-wise;
these are the textbook forms it is checked against (Bar-Shalom et al. 2001 §5.2.3,
§5.5.3)::

    predict   x⁻ = F x,  P⁻ = F P Fᵀ + Q
    innovate  ν = z − H x⁻,  S = H P⁻ Hᵀ + R
    gate      d² = νᵀ S⁻¹ ν  ≤  γ
    score     ln p(z|T) = −½ d² − ½ ln det S − ln 2π
    update    K = P⁻ Hᵀ S⁻¹,  x = x⁻ + K ν,  P = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ (Joseph)
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from mhtrack.mht.gating import Gated, plot_covariances
from mhtrack.models.linalg2 import LOG_2PI, inv2, lmax2, mahalanobis2
from mhtrack.models.motion import POS

#: Below this many track–plot pairs :func:`candidate_pairs` uses the dense (M × N)
#: distances; above it a k-d tree.
DENSE_PAIR_LIMIT = 200_000


def predict(
    x: np.ndarray, P: np.ndarray, F: np.ndarray, Q: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``x⁻ = F x``, ``P⁻ = F P Fᵀ + Q`` (symmetrised)."""
    xp = x @ F.T
    Pp = F @ P @ F.T + Q
    return xp, 0.5 * (Pp + np.swapaxes(Pp, -1, -2))


def _pos_cov(P: np.ndarray) -> np.ndarray:
    """``H P Hᵀ`` for stacked ``P``: the position block."""
    return P[..., POS[:, None], POS[None, :]]


def candidate_pairs(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, gamma: float
) -> tuple[np.ndarray, np.ndarray]:
    """A superset of the pairs with ``d² ≤ γ``: the gate ellipse of track i lies in the disc
    of radius ``sqrt(γ λmax(S_i))``, ``S_i = H P_i Hᵀ + R_max``."""
    M, N = len(x), len(z)
    if M == 0 or N == 0:
        e = np.zeros(0, np.int64)
        return e, e
    R, shared = plot_covariances(R, N)
    Rmax = R if shared else np.eye(2) * lmax2(R).max()
    radius = np.sqrt(gamma * lmax2(_pos_cov(P) + Rmax)) * (1 + 1e-9)
    if M * N <= DENSE_PAIR_LIMIT:
        d = x[:, None, POS] - z[None, :, :]
        ti, pj = np.nonzero(np.einsum("mnk,mnk->mn", d, d) <= radius[:, None] ** 2)
        return ti.astype(np.int64), pj.astype(np.int64)
    hits = cKDTree(z).query_ball_point(x[:, POS], radius)
    counts = np.fromiter((len(h) for h in hits), np.int64, count=M)
    ti = np.repeat(np.arange(M, dtype=np.int64), counts)
    pj = np.fromiter((j for h in hits for j in h), np.int64, count=int(counts.sum()))
    return ti, pj


def gate(x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, gamma: float) -> Gated:
    """Every pair with ``d² ≤ γ`` and its innovation log-likelihood, ordered by track then
    plot (dense distances or a k-d tree for the candidates)."""
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R, shared = plot_covariances(R, len(z))
    ti, pj = candidate_pairs(x, P, z, R, gamma)
    if len(ti) == 0:
        e = np.zeros(0)
        return Gated(ti, pj, e, e)
    S = _pos_cov(P)[ti] + (R if shared else R[pj])
    d2, det = mahalanobis2(z[pj] - x[ti][:, POS], S)
    keep = d2 <= gamma
    ti, pj, d2, det = ti[keep], pj[keep], d2[keep], det[keep]
    order = np.lexsort((pj, ti))
    ti, pj, d2, det = ti[order], pj[order], d2[order], det[order]
    return Gated(ti, pj, d2, -0.5 * (d2 + np.log(det)) - LOG_2PI)


def innovation_loglik(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Dense ``d²`` and ``ln N(ν; 0, S)`` for every track–plot pair, shape (M, N)."""
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R, shared = plot_covariances(R, len(z))
    S = _pos_cov(P)[:, None] + (R if shared else R[None])
    d2, det = mahalanobis2(z[None] - x[:, None, POS], S)
    return d2, -0.5 * (d2 + np.log(det)) - LOG_2PI


def update(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Kalman update of stacked pairs in Joseph form (keeps ``P`` symmetric PSD)."""
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R = np.asarray(R, float)
    S = _pos_cov(P) + R
    K = P[..., :, POS] @ inv2(S)  # (K, 4, 2)
    xn = x + np.einsum("kij,kj->ki", K, z - x[:, POS])
    KH = np.zeros(P.shape)
    KH[..., :, POS] = K
    A = np.eye(4) - KH
    Pn = A @ P @ np.swapaxes(A, -1, -2) + K @ R @ np.swapaxes(K, -1, -2)
    return xn, 0.5 * (Pn + np.swapaxes(Pn, -1, -2))


def two_point_init(
    z1: np.ndarray, z2: np.ndarray, dt: float, R1: np.ndarray, R2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Two-point differencing at the time of ``z2``: ``x = [z2x, (z2x−z1x)/T, z2y,
    (z2y−z1y)/T]`` with its exact covariance (Bar-Shalom et al. 2001 §5.5.3)."""
    z1 = np.asarray(z1, float).reshape(-1, 2)
    z2 = np.asarray(z2, float).reshape(-1, 2)
    n = len(z1)
    R1 = np.broadcast_to(R1, (n, 2, 2))
    R2 = np.broadcast_to(R2, (n, 2, 2))
    x = np.empty((n, 4))
    x[:, POS] = z2
    x[:, [1, 3]] = (z2 - z1) / dt
    P = np.empty((n, 4, 4))
    P[:, 0::2, 0::2] = R2
    P[:, 0::2, 1::2] = R2 / dt
    P[:, 1::2, 0::2] = R2 / dt
    P[:, 1::2, 1::2] = (R1 + R2) / dt**2
    return x, P
