"""Interacting multiple model (IMM) filter of constant-velocity models, batched.

Each track carries ``r`` constant-velocity models that differ only in their acceleration
noise (a *quiet* model for straight flight and a *manoeuvre* model, typically), with
model probabilities ``μ``. Equations (Blom & Bar-Shalom 1988; Bar-Shalom et al. 2001
§11.6.6), for stacked tracks ``xm`` (M, r, 4), ``Pm`` (M, r, 4, 4), ``μ`` (M, r)::

    mode switching   π_ij = P(model j at k | model i at k−1),  π_ii = exp(−dt/τ)
    mixing           μ̄_j = Σ_i π_ij μ_i,   μ_i|j = π_ij μ_i / μ̄_j
                     x0_j = Σ_i μ_i|j x_i,  P0_j = Σ_i μ_i|j [P_i + (x_i − x0_j)(x_i − x0_j)ᵀ]
    predict          x⁻_j = F x0_j,  P⁻_j = F P0_j Fᵀ + Q_j
    likelihood       p(z|T) = Σ_j μ̄_j N(z; H x⁻_j, H P⁻_j Hᵀ + R)
    update           each model's Kalman update; μ_j ∝ μ̄_j N(z; H x⁻_j, S_j)
    on a miss        x_j = x⁻_j, μ_j = μ̄_j
    output           x = Σ_j μ_j x_j,  P = Σ_j μ_j [P_j + (x_j − x)(x_j − x)ᵀ]

The mixture likelihood is what enters the MHT track score (P1 eq. 5) in place of the
single-model innovation likelihood; with one model every formula reduces to the Kalman
filter of :mod:`mhtrack.models.kalman`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from mhtrack.models import imm_rows, kalman
from mhtrack.models.linalg2 import gaussian_loglik2, sym_mahalanobis2
from mhtrack.models.motion import ConstantVelocity, MotionModel, States


@dataclass(frozen=True)
class CVModelSet(MotionModel):
    """``r`` constant-velocity models with acceleration noise stds ``sigmas`` (m/s²) and
    mean sojourn time ``mode_time`` (s) in a model: ``π_ii = exp(−dt/τ)``, the rest of
    the row shared equally by the other models. Initial probabilities are equal.

    As a :class:`~mhtrack.models.motion.MotionModel`: the IMM filter (module docstring),
    scoring a plot by the mixture likelihood ``Σ_j μ̄_j N(z; H x⁻_j, S_j)``."""

    sigmas: tuple[float, ...]
    mode_time: float = 100.0
    #: The score is the models' mixture: the gate's single-Gaussian likelihood is not read.
    reads_gate_loglik: ClassVar[bool] = False

    def __post_init__(self) -> None:
        if len(self.sigmas) < 2:
            raise ValueError("an IMM needs at least two models")
        if not all(math.isfinite(s) and s >= 0 for s in self.sigmas):
            raise ValueError(f"IMM model sigmas must be finite and >= 0, got {self.sigmas}")
        if not (math.isfinite(self.mode_time) and self.mode_time > 0):
            raise ValueError(f"IMM mode_time must be finite and > 0, got {self.mode_time}")

    @property
    def r(self) -> int:
        return len(self.sigmas)

    def initial_mu(self, n: int) -> np.ndarray:
        """Equal model probabilities for ``n`` new tracks, (n, r)."""
        return np.full((n, self.r), 1.0 / self.r)

    def transition(self, dt: float | np.ndarray) -> np.ndarray:
        """Mode transition matrix ``π`` (r, r) for a scan interval ``dt``, or (M, r, r) for
        one interval per row; ``π_ii = exp(−|dt|/τ)`` (a negative ``dt``, a plot slightly
        older than the track, still lets the mode change)."""
        if np.ndim(dt) == 0:
            return _transition(self.r, self.mode_time, float(dt))
        stay = np.exp(-np.abs(np.asarray(dt, float)) / self.mode_time)
        pi = np.repeat(((1.0 - stay) / (self.r - 1))[:, None, None], self.r, axis=1)
        pi = np.repeat(pi, self.r, axis=2)
        idx = np.arange(self.r)
        pi[:, idx, idx] = stay[:, None]
        return pi

    def predict_models(
        self, xm: np.ndarray, Pm: np.ndarray, mu: np.ndarray, dt: float | np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Mixing and per-model prediction: ``(x⁻, P⁻, μ̄)`` (module docstring); ``dt``
        one interval or one per row."""
        mubar, pim, Q = self.mixing(mu, dt)
        xp, Pp = _mix_predict(xm, Pm, mu, mubar, pim, dt, Q)
        return xp, Pp, mubar

    def mixing(self, mu: np.ndarray, dt: float | np.ndarray) -> tuple[np.ndarray, ...]:
        """``(μ̄, π, Q)`` of :meth:`predict_models`: ``π`` (1, r, r) or (M, r, r), ``Q``
        (r, 4, 4) or (M, r, 4, 4)."""
        if np.ndim(dt) == 0:  # one interval: π and Q are the interval's (cached) constants
            pim, Q = _interval_constants(self.r, self.mode_time, self.sigmas, float(dt))
            return mu @ pim[0], pim, Q  # μ̄ (M, r)
        pi = self.transition(dt)
        mubar = np.einsum("mi,mij->mj", mu, pi)
        Q = np.stack([ConstantVelocity(s).Q(dt) for s in self.sigmas], axis=-3)
        return mubar, pi, Q

    # ------------------------------------------------------------------ MotionModel
    @property
    def n_models(self) -> int:
        return self.r

    def predict(self, states: States, dt: float | np.ndarray) -> States:
        """Mixing and prediction of every model; ``x, P`` their mixture (for gating).
        Past :data:`BLOCK` rows the work goes block by block of rows, so that its
        temporaries stay in the CPU cache: every operation is row by row, so the floats
        are those of one pass (``tests/models/test_inplace_identity.py``)."""
        xm, Pm, mu = states.xm, states.Pm, states.mu
        mubar, pim, Q = self.mixing(mu, dt)
        M = len(mu)
        if (k := imm_rows.kernels(M)) is not None:  # the same floats, compiled
            out = States(np.empty((M, 4)), np.empty((M, 4, 4)), np.empty(xm.shape),
                         np.empty(Pm.shape), mubar)
            k["predict"](*_c(xm, Pm, mu, mubar, pim, np.atleast_1d(np.asarray(dt, float)),
                             Q if Q.ndim == 4 else Q[None]),
                         out.x, out.P, out.xm, out.Pm)
            return out
        if M <= BLOCK:
            xp, Pp = _mix_predict(xm, Pm, mu, mubar, pim, dt, Q)
            return States(*combine(xp, Pp, mubar), xp, Pp, mubar)
        out = States(np.empty((M, 4)), np.empty((M, 4, 4)), np.empty(xm.shape),
                     np.empty(Pm.shape), mubar)
        per_row = np.ndim(dt) > 0
        for s in range(0, M, BLOCK):
            b = slice(s, s + BLOCK)
            xp, Pp = _mix_predict(xm[b], Pm[b], mu[b], mubar[b], pim[b] if per_row else pim,
                                  dt[b] if per_row else dt, Q[b] if per_row else Q)
            out.x[b], out.P[b] = combine(xp, Pp, mubar[b])
            out.xm[b], out.Pm[b] = xp, Pp
        return out

    def update(self, states: States, z: np.ndarray, R: np.ndarray,
               posterior: Posterior | None = None) -> States:
        """Each model's update and the posterior probabilities (:func:`update`); ``x, P``
        their mixture. ``posterior``: the rows' :class:`Posterior` when already known
        (:meth:`gating_scores`: the same floats). Block by block of rows as
        :meth:`predict` (the same floats)."""
        K = len(states.mu)
        if (k := imm_rows.kernels(K)) is not None:  # the same floats, compiled
            R = np.asarray(R, float)
            if posterior is None:
                _, mu, total = _mixture(states.mu, model_logliks(states.xm, states.Pm, z, R))
                mu /= total[:, None]
            else:
                mu = posterior.probabilities()
            out = States(np.empty((K, 4)), np.empty((K, 4, 4)), np.empty(states.xm.shape),
                         np.empty(states.Pm.shape), mu)
            k["update"](*_c(states.xm, states.Pm, mu, z, R if R.ndim == 3 else R[None]),
                        out.x, out.P, out.xm, out.Pm)
            return out
        if K <= BLOCK:
            xm, Pm, mu = update(states.xm, states.Pm, states.mu, z, R, posterior)
            return States(*combine(xm, Pm, mu), xm, Pm, mu)
        R = np.asarray(R, float)
        out = States(np.empty((K, 4)), np.empty((K, 4, 4)), np.empty(states.xm.shape),
                     np.empty(states.Pm.shape), np.empty(states.mu.shape))
        for s in range(0, K, BLOCK):
            b = slice(s, s + BLOCK)
            xm, Pm, mu = update(states.xm[b], states.Pm[b], states.mu[b], z[b],
                                R if R.ndim == 2 else R[b],
                                None if posterior is None else posterior[b])
            out.x[b], out.P[b] = combine(xm, Pm, mu)
            out.xm[b], out.Pm[b], out.mu[b] = xm, Pm, mu
        return out

    def children_states(self, pred: States, parent: np.ndarray, plot: np.ndarray,
                        pair: np.ndarray, z: np.ndarray, R: np.ndarray,
                        posterior: Any) -> States | None:
        """The children's states in one compiled pass (:func:`mhtrack.models.imm_rows.
        grow_rows`: the floats of ``pred.take(parent)`` and :meth:`update` of the updates
        with ``posterior[pair]``), or ``None`` where the compiled loops are not used."""
        C = len(parent)
        if not isinstance(posterior, Posterior) or (k := imm_rows.kernels(C)) is None:
            return None
        r = self.r
        out = States(np.empty((C, 4)), np.empty((C, 4, 4)), np.empty((C, r, 4)),
                     np.empty((C, r, 4, 4)), np.empty((C, r)))
        R = np.asarray(R, float)
        k["grow"](*_c(pred.x, pred.P, pred.xm, pred.Pm, pred.mu),
                  *(np.ascontiguousarray(a, dtype=np.int64) for a in (parent, plot, pair)),
                  *_c(posterior.weight, posterior.total, z, R if R.ndim == 3 else R[None]),
                  out.x, out.P, out.xm, out.Pm, out.mu)
        return out

    def gating_loglik(
        self, pred: States, track: np.ndarray, plot: np.ndarray, z: np.ndarray,
        R: np.ndarray, loglik: np.ndarray,
    ) -> np.ndarray:
        """The mixture likelihood ``ln Σ_j μ̄_j N(z; H x⁻_j, S_j)`` of the gated pairs."""
        return self.gating_scores(pred, track, plot, z, R, loglik)[0]

    def gating_scores(
        self, pred: States, track: np.ndarray, plot: np.ndarray, z: np.ndarray,
        R: np.ndarray, loglik: np.ndarray,
    ) -> tuple[np.ndarray, Posterior | None]:
        """:meth:`gating_loglik` and, per pair, the posterior model probabilities ``μ_j``
        of its update (module docstring; the floats :func:`update` computes) as a
        :class:`Posterior`, which :meth:`update` then reuses."""
        if len(track) == 0:
            return np.zeros(0), None
        # only the position terms of each pair's leaf are copied, not its whole state
        terms = [t.take(track, axis=0) for t in _position_terms(pred.xm, pred.Pm)]
        ll = _logliks(terms, z.take(plot, axis=0), R if R.ndim == 2 else R.take(plot, axis=0))
        lg, weight, total = _mixture(pred.mu.take(track, axis=0), ll)
        return lg, Posterior(weight, total)

    def new_states(self, x: np.ndarray, P: np.ndarray) -> States:
        """Every model at ``x``, ``P`` with equal probabilities."""
        r = self.r
        return States(x, P, np.repeat(x[:, None], r, axis=1), np.repeat(P[:, None], r, axis=1),
                      self.initial_mu(len(x)))


def _c(*arrays: np.ndarray) -> list[np.ndarray]:
    """C-contiguous float arrays (one compiled signature for every call)."""
    return [np.ascontiguousarray(a, dtype=float) for a in arrays]


#: Rows per block of :meth:`CVModelSet.predict` (a block's temporaries, ~40 arrays of
#: up to 2·16 floats a row, fit in the CPU's cache).
BLOCK = 1024


def _mix_predict(xm: np.ndarray, Pm: np.ndarray, mu: np.ndarray, mubar: np.ndarray,
                 pim: np.ndarray, dt: float | np.ndarray,
                 Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mixing (``μ_i|j``, ``x0_j``, ``P0_j``) and each model's prediction, row by row,
    given ``μ̄``, ``π`` and ``Q`` (:meth:`CVModelSet.mixing`)."""
    w = pim * mu[:, :, None] / np.maximum(mubar, 1e-300)[:, None, :]  # (M,i,j)
    x0 = _mix_sum(w[..., None], xm[:, :, None, :])  # (M, j, 4)
    d = xm[:, :, None, :] - x0[:, None, :, :]  # (M, i, j, 4)
    wd = w[..., None] * d
    tmp = np.empty_like(Pm)  # (M, j, 4, 4) scratch of both sums
    P0 = _mix_sum(w[..., None, None], Pm[:, :, None], tmp=tmp)
    P0 += _mix_sum(wd[..., :, None], d[..., None, :], tmp=tmp)
    return kalman.predict_cv(x0, P0, dt, Q, overwrite=True)  # every model at once


@functools.lru_cache(maxsize=64)
def _transition(r: int, mode_time: float, dt: float) -> np.ndarray:
    """``π`` (r, r) for one interval (read-only; cached: synchronous scans repeat ``dt``)."""
    stay = math.exp(-dt / mode_time)
    pi = np.full((r, r), (1.0 - stay) / (r - 1))
    np.fill_diagonal(pi, stay)
    pi.setflags(write=False)
    return pi


@functools.lru_cache(maxsize=64)
def _interval_constants(r: int, mode_time: float, sigmas: tuple[float, ...],
                        dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``(π[None], Q)`` of one interval for :meth:`CVModelSet.mixing`: :func:`_transition`
    as (1, r, r) and :func:`_process_noise` (read-only; one cache look-up a scan: 0.05
    against 74 µs computed, ~5 % of a crossing scan — ``docs/performance.md``, *Speed
    idioms in one place*)."""
    return _transition(r, mode_time, dt)[None, :, :], _process_noise(sigmas, dt)


@functools.lru_cache(maxsize=64)
def _process_noise(sigmas: tuple[float, ...], dt: float) -> np.ndarray:
    """Every model's ``Q(dt)``, (r, 4, 4) (read-only; cached as :func:`_transition`)."""
    q = np.stack([ConstantVelocity(s).Q(dt) for s in sigmas])
    q.setflags(write=False)
    return q


def _mix_sum(w: np.ndarray, a: np.ndarray, tmp: np.ndarray | None = None) -> np.ndarray:
    """``Σ_i w_i a_i`` over axis 1, summed in model order ``((w_0 a_0 + w_1 a_1) + …)``:
    the products and the order of ``np.einsum``'s sum, in a few whole-array operations,
    accumulated in place (the same floats as ``out = out + w_i a_i``). ``tmp``: a scratch
    array of the result's shape to reuse (else one is allocated)."""
    out = np.multiply(w[:, 0], a[:, 0])
    if w.shape[1] > 1:
        tmp = np.empty_like(out) if tmp is None else tmp
        for i in range(1, w.shape[1]):
            np.multiply(w[:, i], a[:, i], out=tmp)
            out += tmp
    return out


def combine(xm: np.ndarray, Pm: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Moment-matched single Gaussian of the model mixture: ``(x, P)``, (M, 4), (M, 4, 4)."""
    x = _mix_sum(mu[..., None], xm)
    d = xm - x[:, None, :]
    P = _mix_sum(mu[..., None, None], Pm)
    spread = _mix_sum((mu[..., None] * d)[..., None], d[..., None, :], tmp=np.empty_like(P))
    P += spread
    return x, kalman.symmetrised(P, out=spread)


def model_logliks(xm: np.ndarray, Pm: np.ndarray, z: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Per row and model, ``ln N(z; H x_j, H P_j Hᵀ + R)``: ``xm`` (K, r, 4), ``Pm``
    (K, r, 4, 4), ``z`` (K, 2), ``R`` (2, 2) or (K, 2, 2). Returns (K, r)."""
    return _logliks(_position_terms(xm, Pm), z, R)


def _position_terms(xm: np.ndarray, Pm: np.ndarray) -> tuple[np.ndarray, ...]:
    """What the plot likelihood reads of each model's state: ``x, y, Pxx, Pxy, Pyy``."""
    return xm[..., 0], xm[..., 2], Pm[..., 0, 0], Pm[..., 0, 2], Pm[..., 2, 2]


def _logliks(terms: tuple[np.ndarray, ...] | list[np.ndarray], z: np.ndarray,
             R: np.ndarray) -> np.ndarray:
    """:func:`model_logliks` from the :func:`_position_terms` (K, r) of the rows."""
    x, y, pxx, pxy, pyy = terms
    R = np.asarray(R, float)
    Rb = R if R.ndim == 2 else R[:, None]
    s00 = pxx + Rb[..., 0, 0]
    s01 = pxy + Rb[..., 0, 1]
    s11 = pyy + Rb[..., 1, 1]
    n0 = z[:, None, 0] - x
    n1 = z[:, None, 1] - y
    d2, det = sym_mahalanobis2(n0, n1, s00, s01, s11)
    return gaussian_loglik2(d2, det)


def _row_max(a: np.ndarray) -> np.ndarray:
    """``a.max(axis=1)`` of (K, r) as ``r − 1`` whole-column ``np.maximum`` (the same
    values: a maximum is one of its operands)."""
    r = a.shape[1]
    out = np.maximum(a[:, 0], a[:, 1]) if r > 1 else a[:, 0].copy()
    for j in range(2, r):
        out = np.maximum(out, a[:, j])
    return out


def _row_sum(a: np.ndarray) -> np.ndarray:
    """``a.sum(axis=1)`` of (K, r): for ``r < 8`` NumPy adds a row's entries in order,
    ``((a_0 + a_1) + a_2) + …``, done here as whole-column additions (the same floats,
    without a reduction over a short axis); wider rows take NumPy's own sum."""
    if a.shape[1] >= 8:
        return a.sum(axis=1)
    r = a.shape[1]
    out = a[:, 0] + a[:, 1] if r > 1 else a[:, 0].copy()
    for j in range(2, r):
        out = out + a[:, j]
    return out


@dataclass(frozen=True, slots=True)
class Posterior:
    """Posterior model probabilities of K updates as the mixture likelihood leaves them
    (:func:`_mixture`): ``weight`` (K, r) ``exp(a_j − m)`` and ``total`` (K,) their sum;
    ``μ_j = weight_j / total`` (:meth:`probabilities`), divided only for the rows used."""

    weight: np.ndarray
    total: np.ndarray

    def __getitem__(self, rows: np.ndarray | slice) -> Posterior:
        """Rows ``rows`` (an index array or a slice)."""
        if isinstance(rows, slice):
            return Posterior(self.weight[rows], self.total[rows])
        return Posterior(self.weight.take(rows, axis=0), self.total.take(rows))

    def probabilities(self) -> np.ndarray:
        """``μ`` (K, r), ``weight / total`` (a new array)."""
        return np.divide(self.weight, self.total[:, None])


def _mixture(mubar: np.ndarray, ll: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(ln Σ_j μ̄_j exp(ll_j), w, Σ_j w_j)`` per row, ``mubar`` and ``ll`` (K, r): the
    log-sum-exp ``m + ln Σ_j exp(a_j − m)`` of ``a = ln μ̄ + ll``, ``m = max_j a_j``, and
    the weights ``w_j = exp(a_j − m)`` of the posterior model probabilities
    ``μ_j = w_j / Σ_k w_k``, which share ``a``, ``m`` and the sum."""
    with np.errstate(divide="ignore"):
        a = np.log(mubar) + ll
    m = _row_max(a)
    a -= m[:, None]
    w = np.exp(a)
    total = _row_sum(w)
    lg = np.log(total)
    lg += m  # m + ln Σ (a sum is the same either way round)
    return lg, w, total


def mixture_loglik(mubar: np.ndarray, ll: np.ndarray) -> np.ndarray:
    """``ln Σ_j μ̄_j exp(ll_j)`` per row (log-sum-exp), ``mubar`` and ``ll`` (K, r)."""
    return _mixture(mubar, ll)[0]


def update(
    xm: np.ndarray, Pm: np.ndarray, mubar: np.ndarray, z: np.ndarray, R: np.ndarray,
    posterior: Posterior | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each model's Kalman update with plot ``z`` (one plot per row) and the posterior
    model probabilities ``μ_j ∝ μ̄_j N(z; H x⁻_j, S_j)`` (:func:`_mixture`): ``(x, P, μ)``.
    ``posterior``: those probabilities when already computed (by the gate)."""
    K, r = mubar.shape
    if posterior is None:
        _, mu, total = _mixture(mubar, model_logliks(xm, Pm, z, R))
        mu /= total[:, None]
    else:
        mu = posterior.probabilities()
    R = np.asarray(R, float)
    Rr = R if R.ndim == 2 else np.repeat(R, r, axis=0)
    xn, Pn = kalman.update_position(xm.reshape(K * r, 4), Pm.reshape(K * r, 4, 4),
                                    np.repeat(z, r, axis=0), Rr)
    return xn.reshape(K, r, 4), Pn.reshape(K, r, 4, 4), mu
