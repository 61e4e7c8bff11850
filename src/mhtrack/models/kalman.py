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

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from mhtrack.models.motion import POS

LOG_2PI = float(np.log(2 * np.pi))

#: Below this many track–plot pairs the dense (M × N) computation is used; above it the
#: candidates are found with a k-d tree first, so memory stays O(pairs in gates).
DENSE_PAIR_LIMIT = 200_000


def gate_threshold(probability: float) -> float:
    """χ² gate ``γ`` with 2 degrees of freedom holding ``probability`` of true plots."""
    if not 0.0 < probability < 1.0:
        raise ValueError(f"gate probability must be in (0, 1), got {probability}")
    # χ² with 2 d.o.f. is exponential with mean 2: P(d² ≤ γ) = 1 − exp(−γ/2), so the
    # quantile is exact in closed form (and needs no scipy.stats at import time).
    return -2.0 * math.log1p(-probability)


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


# --------------------------------------------------------------------------------------
# Fast paths for thousands of stacked tracks (added for the MHT hot loop). Same contracts
# as the general functions above, specialised to the constant-velocity state
# ``[x, vx, y, vy]`` and position plots, computed element-wise instead of with stacks of
# small matrix products. Results agree with the general functions to rounding.


def predict_cv(
    x: np.ndarray, P: np.ndarray, dt: float, Q: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`predict` for the constant-velocity ``F(dt) = I + dt·E`` (``E`` adds each
    velocity to its position): ``x⁻ = F x``, ``P⁻ = F P Fᵀ + Q`` done as two row/column
    updates ``P[pos] += dt·P[vel]`` on the whole stack."""
    xp = x.copy()
    xp[:, 0::2] += dt * x[:, 1::2]
    Pp = P.copy()
    Pp[:, 0::2, :] += dt * Pp[:, 1::2, :]
    Pp[:, :, 0::2] += dt * Pp[:, :, 1::2]
    Pp += Q
    return xp, 0.5 * (Pp + np.swapaxes(Pp, -1, -2))


def update_position(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`update` for position plots, element-wise: with ``A = P Hᵀ`` (two columns of
    ``P``), ``K = A S⁻¹``, ``x⁺ = x + K ν``, ``P⁺ = P − K Aᵀ`` (standard form, symmetrised;
    the Joseph form of :func:`update` differs by rounding only). ``R`` is (2, 2) shared or
    (K, 2, 2) per pair."""
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R = np.asarray(R, float)
    a0, a1 = P[:, :, 0], P[:, :, 2]  # columns of P Hᵀ, (K, 4)
    s00 = a0[:, 0] + R[..., 0, 0]
    s01 = a0[:, 2] + R[..., 0, 1]
    s11 = a1[:, 2] + R[..., 1, 1]
    det = s00 * s11 - s01 * s01
    i00, i01, i11 = s11 / det, -s01 / det, s00 / det
    k0 = a0 * i00[:, None] + a1 * i01[:, None]  # columns of K, (K, 4)
    k1 = a0 * i01[:, None] + a1 * i11[:, None]
    nu = z - x[:, POS]
    xn = x + k0 * nu[:, :1] + k1 * nu[:, 1:]
    Pn = P - (k0[:, :, None] * a0[:, None, :] + k1[:, :, None] * a1[:, None, :])
    return xn, 0.5 * (Pn + np.swapaxes(Pn, -1, -2))


def _sweep_boxes(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, shared: bool, gamma: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Candidate search of :func:`gate_sweep`: for each (track, strip) query, the range
    ``lo:hi`` of the plots in ``order`` inside the track's gate box. Returns
    ``(tq, lo, hi, order)``."""
    M, N = len(x), len(z)
    # box half-widths with the largest plot covariance (a superset; exact test later)
    rxx = R[0, 0] if shared else R[:, 0, 0].max()
    ryy = R[1, 1] if shared else R[:, 1, 1].max()
    hx = np.sqrt(gamma * (P[:, 0, 0] + rxx)) * (1 + 1e-9) + 1e-9
    hy = np.sqrt(gamma * (P[:, 2, 2] + ryy)) * (1 + 1e-9) + 1e-9
    x0 = float(z[:, 0].min())
    y0 = float(z[:, 1].min())
    height = float(z[:, 1].max()) - y0 + 1.0  # keys of different strips never interleave
    # strip width: the mean box width, but at most ~4·sqrt(N) strips
    width = max(2 * float(hx.mean()), float(np.ptp(z[:, 0])) / (4 * np.sqrt(N) + 1), 1e-6)
    col = np.floor((z[:, 0] - x0) / width).astype(np.int64)
    order = np.lexsort((z[:, 1], col))
    key = col[order] * height + (z[order, 1] - y0)
    n_cols = int(col.max()) + 1
    c_lo = np.clip(np.floor((x[:, 0] - hx - x0) / width).astype(np.int64), 0, n_cols)
    c_hi = np.clip(np.floor((x[:, 0] + hx - x0) / width).astype(np.int64), -1, n_cols - 1)
    nc = np.maximum(c_hi - c_lo + 1, 0)
    tq = np.repeat(np.arange(M, dtype=np.int64), nc)
    cq = np.repeat(c_lo - np.cumsum(nc) + nc, nc) + np.arange(int(nc.sum()))
    ylo = np.clip(x[tq, 2] - hy[tq] - y0, -0.5, height - 0.5)
    yhi = np.clip(x[tq, 2] + hy[tq] - y0, -0.5, height - 0.5)
    lo = np.searchsorted(key, cq * height + ylo, side="left")
    hi = np.searchsorted(key, cq * height + yhi, side="right")
    return tq, lo, hi, order


def gate_candidate_counts(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, gamma: float
) -> np.ndarray:
    """Per track, how many plots :func:`gate_sweep` will test exactly (those in its gate's
    bounding box) — an upper bound on its gated plots, found without forming any pair.
    Lets a caller bound the work of gating before doing it."""
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R, shared = _plot_R(R, len(z))
    if len(x) == 0 or len(z) == 0:
        return np.zeros(len(x), np.int64)
    tq, lo, hi, _ = _sweep_boxes(x, P, z, R, shared, gamma)
    return np.bincount(tq, weights=hi - lo, minlength=len(x)).astype(np.int64)


def gate_sweep(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, gamma: float
) -> Gated:
    """:func:`gate` (same pairs, same order, same ``d2`` and ``loglik``) with the
    candidates found by a sweep instead of an M × N matrix or a k-d tree.

    The gate ellipse ``νᵀ S⁻¹ ν ≤ γ`` lies inside the box ``|νx| ≤ √(γ S_xx)``,
    ``|νy| ≤ √(γ S_yy)``. Plots are bucketed into vertical strips and sorted by ``y``
    within each; every track looks up, in each strip its box overlaps, the plots in its
    ``y`` range with one vectorised ``searchsorted``. Work and memory are
    O(M·strips-per-box + pairs in boxes), whatever M × N is.
    """
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    M, N = len(x), len(z)
    R, shared = _plot_R(R, N)
    e = np.zeros(0, np.int64)
    if M == 0 or N == 0:
        return Gated(e, e, np.zeros(0), np.zeros(0))
    tq, lo, hi, order = _sweep_boxes(x, P, z, R, shared, gamma)
    cnt = hi - lo
    ti = np.repeat(tq, cnt)
    pj = order[np.repeat(lo - np.cumsum(cnt) + cnt, cnt) + np.arange(int(cnt.sum()))]
    if ti.size == 0:
        return Gated(e, e, np.zeros(0), np.zeros(0))
    if shared:
        s00 = P[ti, 0, 0] + R[0, 0]
        s01 = P[ti, 0, 2] + R[0, 1]
        s11 = P[ti, 2, 2] + R[1, 1]
    else:
        s00 = P[ti, 0, 0] + R[pj, 0, 0]
        s01 = P[ti, 0, 2] + R[pj, 0, 1]
        s11 = P[ti, 2, 2] + R[pj, 1, 1]
    n0 = z[pj, 0] - x[ti, 0]
    n1 = z[pj, 1] - x[ti, 2]
    det = s00 * s11 - s01 * s01
    d2 = (s11 * n0 * n0 - 2 * s01 * n0 * n1 + s00 * n1 * n1) / det
    keep = d2 <= gamma
    ti, pj, d2, det = ti[keep], pj[keep], d2[keep], det[keep]
    # pairs are grouped by track already; timsort on the nearly sorted key is ~linear
    o = np.argsort(ti * N + pj, kind="stable")
    ti, pj, d2, det = ti[o], pj[o], d2[o], det[o]
    return Gated(ti, pj, d2, -0.5 * (d2 + np.log(det)) - LOG_2PI)
