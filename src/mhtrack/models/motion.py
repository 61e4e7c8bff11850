"""Motion models: the constant-velocity model (P1 §1.1, eq. 1) and the interface through
which the MHT predicts, scores and updates its leaves (:class:`MotionModel`).

State ``x = [x, vx, y, vy]``; ``F = blkdiag(F1, F1)`` with ``F1 = [[1, T], [0, 1]]`` and
``Q = blkdiag(Q1, Q1)·σv²`` with ``Q1 = [[T⁴/4, T³/2], [T³/2, T²]]`` (piecewise-constant
white acceleration, Bar-Shalom et al. 2001 §6.3.3).

A :class:`MotionModel` works on :class:`States`: the stacked states of many tracks, with
``r`` per-model arrays when the model is a mixture (the IMM, :mod:`mhtrack.models.imm`)
and ``r = 0`` for a single filter (:class:`ConstantVelocity`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from mhtrack.models import kalman

#: Measurement matrix of a position sensor, ``H = [[1,0,0,0],[0,0,1,0]]`` (P1 §1.1).
H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
#: Indices of position and velocity in the state vector.
POS = np.array([0, 2])
VEL = np.array([1, 3])


def row_index(idx: np.ndarray) -> np.ndarray:
    """``idx`` (an index array or boolean mask over rows) as row numbers, for
    ``ndarray.take(…, axis=0)`` — the same rows as ``a[idx]``, copied without the cost
    of fancy indexing over trailing axes."""
    idx = np.asarray(idx)
    if idx.dtype == bool:
        return np.flatnonzero(idx)
    return idx if idx.dtype.kind in "iu" else idx.astype(np.intp)


@dataclass(frozen=True, slots=True)
class States:
    """Stacked track states: ``x`` (M, 4), ``P`` (M, 4, 4) — for a mixture their
    moment-matched Gaussian — and per model ``xm`` (M, r, 4), ``Pm`` (M, r, 4, 4), ``mu``
    (M, r) (``r = 0``: a single model)."""

    x: np.ndarray
    P: np.ndarray
    xm: np.ndarray
    Pm: np.ndarray
    mu: np.ndarray

    def take(self, idx: np.ndarray) -> States:
        """Rows ``idx`` (an index array or boolean mask; copies)."""
        idx = row_index(idx)
        return States(self.x.take(idx, axis=0), self.P.take(idx, axis=0),
                      self.xm.take(idx, axis=0), self.Pm.take(idx, axis=0),
                      self.mu.take(idx, axis=0))

    def put(self, idx: np.ndarray, other: States) -> None:
        """Overwrite rows ``idx`` with ``other``'s rows (in place)."""
        self.x[idx], self.P[idx] = other.x, other.P
        self.xm[idx], self.Pm[idx], self.mu[idx] = other.xm, other.Pm, other.mu


class MotionModel(ABC):
    """What the MHT needs of a motion model: predict, score a plot, update, start a track.

    Required: :attr:`n_models`, :meth:`predict`, :meth:`update`. Optional hooks (defaults
    for a single Gaussian filter): :meth:`gating_loglik`, :meth:`gating_scores` (the score
    and what :meth:`update` may reuse; ``update`` is given ``posterior=`` only when it
    returns one), :attr:`reads_gate_loglik`, :meth:`new_states`.
    """

    #: Whether :meth:`gating_scores` reads its ``loglik`` argument (the single Gaussian's
    #: of ``x, P``); a model that does not gets ``None`` there, not computed by the gate.
    reads_gate_loglik: ClassVar[bool] = True

    @property
    @abstractmethod
    def n_models(self) -> int:
        """``r``, the per-model arrays each track carries (0 for a single filter)."""

    @abstractmethod
    def predict(self, states: States, dt: float | np.ndarray) -> States:
        """The states ``dt`` seconds later (``x, P`` are what gating uses); ``dt`` one
        interval for all rows or one per row (M,) — asynchronous plots, each track
        predicted to its own plot's time. A negative ``dt`` (a plot slightly older than
        the track's state, frames of two radars overlapping) moves the mean back and
        still adds process noise (``Q`` is a positive semi-definite function of ``dt``)."""

    @abstractmethod
    def update(self, states: States, z: np.ndarray, R: np.ndarray,
               posterior: Any = None) -> States:
        """Each predicted row updated with its plot ``z`` (K, 2); ``R`` (2, 2) or (K, 2, 2).
        ``posterior``: the rows (``reuse[rows]``) of what :meth:`gating_scores` returned
        for reuse (``None``: compute everything)."""

    def gating_loglik(
        self, pred: States, track: np.ndarray, plot: np.ndarray, z: np.ndarray,
        R: np.ndarray, loglik: np.ndarray,
    ) -> np.ndarray:
        """``ln p(z|T)`` of the gated pairs (``track``, ``plot``) for the track score.
        Default: ``loglik``, the Gaussian innovation log-likelihood of ``x, P`` computed
        by the gate — exact for a single filter."""
        return loglik

    def gating_scores(
        self, pred: States, track: np.ndarray, plot: np.ndarray, z: np.ndarray,
        R: np.ndarray, loglik: np.ndarray,
    ) -> tuple[np.ndarray, Any]:
        """``(gating_loglik(…), reuse)``: ``reuse`` (rows by ``reuse[rows]``, or ``None``) is what
        :meth:`update` of the pair may take as ``posterior`` instead of recomputing it.
        Default: :meth:`gating_loglik` and ``None``."""
        return self.gating_loglik(pred, track, plot, z, R, loglik), None

    def children_states(self, pred: States, parent: np.ndarray, plot: np.ndarray,
                        pair: np.ndarray, z: np.ndarray, R: np.ndarray,
                        posterior: Any) -> States | None:
        """Optional: the children's states in one pass — a miss (``plot < 0``) its
        parent's prediction ``pred[parent]``, an update :meth:`update` of it with
        ``z[plot]`` (``R`` shared or by plot) and ``posterior[pair]`` — the same floats, or
        ``None`` (default) to let the caller take the rows and update them."""
        return None

    def new_states(self, x: np.ndarray, P: np.ndarray) -> States:
        """States of new tracks starting at ``x``, ``P``. Default: no per-model arrays."""
        n = len(x)
        return States(x, P, np.zeros((n, 0, 4)), np.zeros((n, 0, 4, 4)), np.zeros((n, 0)))


@dataclass(frozen=True)
class ConstantVelocity(MotionModel):
    """Nearly-constant-velocity model with acceleration noise standard deviation ``sigma_v``
    (m/s²); P1 uses ``σv² = 100``. As a :class:`MotionModel`, the Kalman filter of
    :mod:`mhtrack.models.kalman`."""

    sigma_v: float = 10.0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.sigma_v) and self.sigma_v >= 0):
            raise ValueError(f"sigma_v must be finite and >= 0, got {self.sigma_v}")

    @staticmethod
    def F(dt: float) -> np.ndarray:
        """State transition ``F(T)`` (P1 §1.1)."""
        f1 = np.array([[1.0, dt], [0.0, 1.0]])
        return np.kron(np.eye(2), f1)

    def Q(self, dt: float | np.ndarray) -> np.ndarray:
        """Process noise covariance ``Q(T)`` (P1 §1.1); (4, 4), or (M, 4, 4) for a per-row
        ``dt`` (M,)."""
        if np.ndim(dt) == 0:
            q1 = np.array([[dt**4 / 4, dt**3 / 2], [dt**3 / 2, dt**2]])
            return np.kron(np.eye(2), q1) * self.sigma_v**2
        d = np.asarray(dt, float)
        q = np.zeros((d.size, 4, 4))
        q[:, 0, 0] = q[:, 2, 2] = d**4 / 4
        q[:, 0, 1] = q[:, 1, 0] = q[:, 2, 3] = q[:, 3, 2] = d**3 / 2
        q[:, 1, 1] = q[:, 3, 3] = d**2
        return q * self.sigma_v**2

    # ------------------------------------------------------------------ MotionModel
    @property
    def n_models(self) -> int:
        return 0

    def predict(self, states: States, dt: float | np.ndarray) -> States:
        """Kalman prediction (:func:`~mhtrack.models.kalman.predict_cv`)."""
        xp, Pp = kalman.predict_cv(states.x, states.P, dt, self.Q(dt))
        return States(xp, Pp, states.xm, states.Pm, states.mu)

    def update(self, states: States, z: np.ndarray, R: np.ndarray,
               posterior: Any = None) -> States:
        """Kalman update (:func:`~mhtrack.models.kalman.update_position`); nothing to
        reuse (``posterior`` is ignored)."""
        x, P = kalman.update_position(states.x, states.P, z, R)
        return States(x, P, states.xm, states.Pm, states.mu)
