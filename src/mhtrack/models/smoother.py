"""Fixed-interval smoothing of tracks' filtered histories (Rauch–Tung–Striebel; IMM-aware).

Every row of a track is a filtered estimate: the state given the plots up to its own time.
An analysis of the whole track (a reference trajectory, as surveillance evaluation tools
reconstruct one) wants the state given *all* of the track's plots. The backward pass runs
from each track's last row to its first over the filtered rows, with irregular intervals
``dt_k = t_{k+1} − t_k`` and ``F = F(dt_k)``, ``Q = Q(dt_k)`` of the tracker's motion model.

One constant-velocity model (Rauch, Tung & Striebel 1965; Bar-Shalom, Li & Kirubarajan
2001 §8.6)::

    P⁻_{k+1} = F P_k Fᵀ + Q,   C_k = P_k Fᵀ (P⁻_{k+1})⁻¹
    xˢ_k = x_k + C_k (xˢ_{k+1} − F x_k),   Pˢ_k = P_k + C_k (Pˢ_{k+1} − P⁻_{k+1}) C_kᵀ

An IMM of ``r`` models (:mod:`mhtrack.models.imm`): Kim's smoother for Markov-switching
linear models (Kim 1994, *J. Econometrics* 60, §2.3), from each row's filtered model
states ``x_i, P_i`` and probabilities ``μ_i``, with ``π = π(dt_k)`` the IMM's own mode
transition::

    μ̄_j = Σ_i π_ij μ_i(k)                       (predicted, as the filter's mixing)
    b_ij = π_ij μ_i(k) μˢ_j(k+1) / μ̄_j            P(m_k = i, m_{k+1} = j | all plots)
    μˢ_i(k) = Σ_j b_ij,  w_j|i = b_ij / μˢ_i(k)
    x_ij, P_ij = the RTS step above from model i's filtered x_i, P_i with model j's Q_j
                 towards model j's smoothed xˢ_j(k+1), Pˢ_j(k+1)
    xˢ_i = Σ_j w_j|i x_ij,  Pˢ_i = Σ_j w_j|i [P_ij + (x_ij − xˢ_i)(x_ij − xˢ_i)ᵀ]
    output  xˢ = Σ_i μˢ_i xˢ_i,  Pˢ = Σ_i μˢ_i [Pˢ_i + (xˢ_i − xˢ)(xˢ_i − xˢ)ᵀ]

With one model every line reduces to the RTS step. At a track's last row the smoothed
estimate is the filtered one. A track's rows are the best hypothesis's at each frame, so
where that choice moved to another branch of the track's tree the step from row ``k`` to
``k+1`` is not one filter's prediction; the backward pass still weighs each row by its
own covariance (the smoothed track follows the later, better-informed branch).

Tracks are smoothed together: step ``s`` of the backward pass is one batch of every
track's ``s``-th row from its end (``O(longest track)`` NumPy steps, not one per row).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.models.imm import CVModelSet, combine
from mhtrack.models.kalman import predict_cv, symmetrised
from mhtrack.models.motion import ConstantVelocity, MotionModel


@dataclass(frozen=True)
class Filtered:
    """Filtered rows of tracks, in any order: ``track`` (n,), ``t`` (n,) the state's time,
    ``x`` (n, 4) ``[x, vx, y, vy]`` and ``P`` (n, 4, 4); for an IMM also ``mu`` (n, r),
    ``xm`` (n, r, 4), ``Pm`` (n, r, 4, 4), each model's filtered state."""

    track: np.ndarray
    t: np.ndarray
    x: np.ndarray
    P: np.ndarray
    mu: np.ndarray | None = None
    xm: np.ndarray | None = None
    Pm: np.ndarray | None = None


def smooth(rows: Filtered, motion: MotionModel) -> tuple[np.ndarray, np.ndarray]:
    """Smoothed ``(x, P)`` of every row, in the rows' order (module docstring): the RTS
    smoother for :class:`~mhtrack.models.motion.ConstantVelocity`, Kim's IMM smoother for
    :class:`~mhtrack.models.imm.CVModelSet` (which needs ``mu, xm, Pm``)."""
    n = len(rows.t)
    if n == 0:
        return np.zeros((0, 4)), np.zeros((0, 4, 4))
    order = np.lexsort((np.arange(n), rows.t, rows.track))
    track, t = rows.track[order], rows.t[order]
    last = np.r_[track[1:] != track[:-1], True]
    rank = _next_end(last) - np.arange(n)  # rows to the track's last row: 0 for it
    if isinstance(motion, CVModelSet):
        if rows.mu is None or rows.xm is None or rows.Pm is None:
            raise ValueError("an IMM's smoother needs each row's model states (mu, xm, Pm)")
        xs, Ps = _imm(motion, t, rank, rows.mu[order], rows.xm[order], rows.Pm[order])
    elif isinstance(motion, ConstantVelocity):
        xs, Ps = _rts(motion, t, rank, rows.x[order], rows.P[order])
    else:
        raise TypeError(f"no smoother for motion model {type(motion).__name__}")
    out_x, out_P = np.empty_like(xs), np.empty_like(Ps)
    out_x[order], out_P[order] = xs, Ps
    return out_x, out_P


def _next_end(last: np.ndarray) -> np.ndarray:
    """For each row, the index of the last row of its track (rows sorted by track)."""
    idx = np.where(last, np.arange(last.size), last.size)
    return np.minimum.accumulate(idx[::-1])[::-1]


def _gain_step(P: np.ndarray, x: np.ndarray, dt: np.ndarray, Q: np.ndarray,
               xs1: np.ndarray, Ps1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One RTS step, batched: filtered ``x, P`` at ``k``, smoothed ``xs1, Ps1`` at
    ``k+1``, interval ``dt`` and ``Q``; leading axes broadcast."""
    xp, Pp = predict_cv(x, P, dt, Q)
    # C = P Fᵀ Pp⁻¹ = (Pp⁻¹ F P)ᵀ, with F P = P + dt·(rows of the velocities)
    FP = P.copy()
    d = np.asarray(dt, float).reshape((-1,) + (1,) * (P.ndim - 1))
    FP[..., 0::2, :] += d * P[..., 1::2, :]
    C = np.swapaxes(np.linalg.solve(Pp, FP), -1, -2)
    xs = x + np.einsum("...ij,...j->...i", C, xs1 - xp)
    Ps = P + C @ (Ps1 - Pp) @ np.swapaxes(C, -1, -2)
    return xs, symmetrised(Ps)


def _rts(motion: ConstantVelocity, t: np.ndarray, rank: np.ndarray, x: np.ndarray,
         P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    xs, Ps = x.copy(), P.copy()
    for s in range(1, int(rank.max()) + 1):
        k = (rank == s).nonzero()[0]
        dt = t[k + 1] - t[k]
        xs[k], Ps[k] = _gain_step(P[k], x[k], dt, motion.Q(dt), xs[k + 1], Ps[k + 1])
    return xs, Ps


def _imm(motion: CVModelSet, t: np.ndarray, rank: np.ndarray, mu: np.ndarray,
         xm: np.ndarray, Pm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r = motion.r
    mus, xms, Pms = mu.copy(), xm.copy(), Pm.copy()
    for s in range(1, int(rank.max()) + 1):
        k = (rank == s).nonzero()[0]
        dt = t[k + 1] - t[k]
        mubar, pi, Q = motion.mixing(mu[k], dt)  # π (M, r, r), Q (M, r, 4, 4)
        b = pi * mu[k][:, :, None] * (mus[k + 1] / np.maximum(mubar, 1e-300))[:, None, :]
        mus_k = b.sum(axis=2)
        w = b / np.maximum(mus_k, 1e-300)[:, :, None]  # w[m, i, j] = w_j|i
        # pairs (i, j): model i's filtered state towards model j's smoothed one
        xij, Pij = _gain_step(
            np.repeat(Pm[k][:, :, None], r, axis=2), np.repeat(xm[k][:, :, None], r, axis=2),
            dt, np.repeat(Q[:, None], r, axis=1),
            np.repeat(xms[k + 1][:, None], r, axis=1), np.repeat(Pms[k + 1][:, None], r, axis=1))
        xi = np.einsum("mij,mijk->mik", w, xij)
        dev = xij - xi[:, :, None, :]
        Pi = (np.einsum("mij,mijkl->mikl", w, Pij)
              + np.einsum("mij,mijk,mijl->mikl", w, dev, dev))
        mus[k] = mus_k / mus_k.sum(axis=1, keepdims=True)
        xms[k], Pms[k] = xi, symmetrised(Pi)
    x, P = combine(xms, Pms, mus)
    return x, P
