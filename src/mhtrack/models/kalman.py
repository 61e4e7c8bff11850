"""Kalman filtering of many tracks against many plots at once.

Tracks are stacked: means ``x`` (M, 4) and covariances ``P`` (M, 4, 4). Plots are ``z``
(N, 2) with either one shared covariance ``R`` (2, 2) or one per plot (N, 2, 2).
No Python loop runs over tracks or track–plot pairs: 2×2 innovation covariances are
inverted in closed form over whole arrays.

Equations (standard Kalman filter, e.g. Bar-Shalom et al. 2001 §5.2.3; P1 eqs. 1–2)::

    predict   x⁻ = F x,  P⁻ = F P Fᵀ + Q
    innovate  ν = z − H x⁻,  S = H P⁻ Hᵀ + R
    gate      d² = νᵀ S⁻¹ ν  ≤  γ   (γ = χ²₂ quantile; d² is χ² with 2 d.o.f.)
    score     ln p(z|T) = −½ d² − ½ ln det S − ln 2π      (innovation log-likelihood)
    update    K = P⁻ Hᵀ S⁻¹,  x = x⁻ + K ν,
              P = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ   (Joseph form)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from scipy.stats import chi2

from mhtrack.models.motion import POS

LOG_2PI = float(np.log(2 * np.pi))

#: Below this many track–plot pairs the dense (M × N) computation is used; above it the
#: candidates are found with a k-d tree first, so memory stays O(pairs in gates).
DENSE_PAIR_LIMIT = 200_000


def gate_threshold(probability: float) -> float:
    """χ² gate ``γ`` with 2 degrees of freedom holding ``probability`` of true plots."""
    if not 0.0 < probability < 1.0:
        raise ValueError(f"gate probability must be in (0, 1), got {probability}")
    return float(chi2.ppf(probability, df=2))


def predict(
    x: np.ndarray, P: np.ndarray, F: np.ndarray, Q: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Predict stacked states: ``x⁻ = F x``, ``P⁻ = F P Fᵀ + Q``."""
    xp = x @ F.T
    Pp = F @ P @ F.T + Q
    return xp, 0.5 * (Pp + np.swapaxes(Pp, -1, -2))


def _inv2(S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse and determinant of stacked symmetric 2×2 matrices."""
    a, b, d = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]
    det = a * d - b * b
    inv = np.empty_like(S)
    inv[..., 0, 0] = d / det
    inv[..., 1, 1] = a / det
    inv[..., 0, 1] = inv[..., 1, 0] = -b / det
    return inv, det


def _pos_cov(P: np.ndarray) -> np.ndarray:
    """``H P Hᵀ`` for stacked ``P``: the position block."""
    return P[..., POS[:, None], POS[None, :]]


def _mahalanobis(nu: np.ndarray, S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``d² = νᵀ S⁻¹ ν`` and ``ln det S`` over stacked pairs."""
    a, b, d = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]
    det = a * d - b * b
    n0, n1 = nu[..., 0], nu[..., 1]
    d2 = (d * n0 * n0 - 2 * b * n0 * n1 + a * n1 * n1) / det
    return d2, np.log(det)


@dataclass(frozen=True, slots=True)
class Gated:
    """Track–plot pairs inside the gate: ``track[i]`` with ``plot[i]``, their Mahalanobis
    distance ``d2`` and innovation log-likelihood ``loglik = ln N(ν; 0, S)``."""

    track: np.ndarray
    plot: np.ndarray
    d2: np.ndarray
    loglik: np.ndarray

    def __len__(self) -> int:
        return len(self.track)


def _plot_R(R: np.ndarray, n: int) -> tuple[np.ndarray, bool]:
    R = np.asarray(R, float)
    if R.shape == (2, 2):
        return R, True
    if R.shape != (n, 2, 2):
        raise ValueError(f"R must be (2, 2) or ({n}, 2, 2), got {R.shape}")
    return R, False


def candidate_pairs(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, gamma: float
) -> tuple[np.ndarray, np.ndarray]:
    """All track–plot pairs that *may* lie in the gate ``d² ≤ γ``, found without forming
    the M × N matrix: the gate ellipse of track i lies inside the disc of radius
    ``sqrt(γ · λmax(S_i))`` with ``S_i = H P_i Hᵀ + R_max``, so a k-d tree ball query on the
    plots returns a superset of the gated pairs (exact test done by the caller)."""
    M, N = len(x), len(z)
    if M == 0 or N == 0:
        e = np.zeros(0, np.int64)
        return e, e
    R, shared = _plot_R(R, N)
    Rmax = R if shared else None
    if Rmax is None:
        # Largest plot covariance bounds every S_ij from above (in the eigenvalue sense).
        tr = R[:, 0, 0] + R[:, 1, 1]
        det = R[:, 0, 0] * R[:, 1, 1] - R[:, 0, 1] ** 2
        lam_r = 0.5 * tr + np.sqrt(np.maximum(0.25 * tr**2 - det, 0.0))
        Rmax = np.eye(2) * lam_r.max()
    S = _pos_cov(P) + Rmax
    tr = S[:, 0, 0] + S[:, 1, 1]
    det = S[:, 0, 0] * S[:, 1, 1] - S[:, 0, 1] ** 2
    lam = 0.5 * tr + np.sqrt(np.maximum(0.25 * tr**2 - det, 0.0))
    radius = np.sqrt(gamma * lam) * (1 + 1e-9)
    if M * N <= DENSE_PAIR_LIMIT:
        d = x[:, None, POS] - z[None, :, :]
        ti, pj = np.nonzero(np.einsum("mnk,mnk->mn", d, d) <= radius[:, None] ** 2)
        return ti.astype(np.int64), pj.astype(np.int64)
    tree = cKDTree(z)
    hits = tree.query_ball_point(x[:, POS], radius)
    counts = np.fromiter((len(h) for h in hits), np.int64, count=M)
    ti = np.repeat(np.arange(M, dtype=np.int64), counts)
    pj = np.fromiter((j for h in hits for j in h), np.int64, count=int(counts.sum()))
    return ti, pj


def gate(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, gamma: float
) -> Gated:
    """Every track–plot pair with ``d² ≤ γ``, with its innovation log-likelihood.

    ``x`` (M, 4), ``P`` (M, 4, 4) are *predicted* states; ``z`` (N, 2); ``R`` (2, 2) or
    (N, 2, 2). Pairs are ordered by track, then plot.
    """
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R, shared = _plot_R(R, len(z))
    ti, pj = candidate_pairs(x, P, z, R, gamma)
    if len(ti) == 0:
        e = np.zeros(0)
        return Gated(ti, pj, e, e)
    S = _pos_cov(P)[ti] + (R if shared else R[pj])
    nu = z[pj] - x[ti][:, POS]
    d2, logdet = _mahalanobis(nu, S)
    keep = d2 <= gamma
    ti, pj, d2, logdet = ti[keep], pj[keep], d2[keep], logdet[keep]
    order = np.lexsort((pj, ti))
    ti, pj, d2, logdet = ti[order], pj[order], d2[order], logdet[order]
    return Gated(ti, pj, d2, -0.5 * (d2 + logdet) - LOG_2PI)


def innovation_loglik(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Dense ``d²`` and ``ln N(ν; 0, S)`` for every track–plot pair, shape (M, N).

    Reference implementation for small problems and tests; :func:`gate` is the hot path.
    """
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R, shared = _plot_R(R, len(z))
    S = _pos_cov(P)[:, None] + (R if shared else R[None])
    nu = z[None] - x[:, None, POS]
    d2, logdet = _mahalanobis(nu, S)
    return d2, -0.5 * (d2 + logdet) - LOG_2PI


def update(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Kalman update of stacked pairs: state ``x[i]``, ``P[i]`` with plot ``z[i]`` and
    covariance ``R[i]`` (or one shared ``R``). Joseph form keeps ``P`` symmetric PSD."""
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R = np.asarray(R, float)
    PHt = P[..., :, POS]  # (K, 4, 2)
    S = _pos_cov(P) + R
    Sinv, _ = _inv2(S)
    K = PHt @ Sinv  # (K, 4, 2)
    nu = z - x[:, POS]
    xn = x + np.einsum("kij,kj->ki", K, nu)
    KH = np.zeros(P.shape)
    KH[..., :, POS] = K
    A = np.eye(4) - KH
    Pn = A @ P @ np.swapaxes(A, -1, -2) + K @ R @ np.swapaxes(K, -1, -2)
    return xn, 0.5 * (Pn + np.swapaxes(Pn, -1, -2))


def two_point_init(
    z1: np.ndarray, z2: np.ndarray, dt: float, R1: np.ndarray, R2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Two-point differencing initialisation at the time of ``z2``:
    ``x = [z2x, (z2x−z1x)/T, z2y, (z2y−z1y)/T]`` with its exact covariance
    (Bar-Shalom et al. 2001 §5.5.3). Stacked over rows of ``z1``, ``z2`` (n, 2)."""
    z1 = np.asarray(z1, float).reshape(-1, 2)
    z2 = np.asarray(z2, float).reshape(-1, 2)
    n = len(z1)
    R1 = np.broadcast_to(R1, (n, 2, 2))
    R2 = np.broadcast_to(R2, (n, 2, 2))
    x = np.empty((n, 4))
    x[:, POS] = z2
    x[:, [1, 3]] = (z2 - z1) / dt
    P = np.empty((n, 4, 4))
    pp = R2
    pv = R2 / dt
    vv = (R1 + R2) / dt**2
    P[:, 0::2, 0::2] = pp
    P[:, 0::2, 1::2] = pv
    P[:, 1::2, 0::2] = pv
    P[:, 1::2, 1::2] = vv
    return x, P
