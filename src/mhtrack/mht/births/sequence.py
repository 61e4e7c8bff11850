"""The birth score of an initiated plot sequence: the log-likelihood ratio "target vs
clutter" that an every-plot tree would give the same branch (``docs/mht.md``).

The one-point birth score of its first plot, then, scan by scan, the motion model's
prediction and ``ΔL = ln(1 − P_D)`` on a miss or ``ΔL = ln p(z|T) + ln P_D − ln(κ̂(z) + λ_v)``
on a plot (``κ̂`` as estimated when that plot's scan was processed), the motion model's
update of the one-point initialisation (:func:`sequence_score`). The SPRT thresholds keep
their meaning; ``peak`` is the running maximum along the branch.
"""

from __future__ import annotations

import numpy as np

from mhtrack.mht.scoring import birth_score, update_increment
from mhtrack.mht.tree import one_point_state
from mhtrack.models.linalg2 import LOG_2PI, det2, gaussian_loglik2, sym_mahalanobis2
from mhtrack.models.motion import MotionModel, States


def innovation_loglik(states: States, z: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Per row, ``ln N(z; H x, H P Hᵀ + R)`` of ``states.x, P`` with plot ``z`` (K, 2) and
    ``R`` (K, 2, 2)."""
    x, P = states.x, states.P
    d2, det = sym_mahalanobis2(z[:, 0] - x[:, 0], z[:, 1] - x[:, 2], P[:, 0, 0] + R[:, 0, 0],
                               P[:, 0, 2] + R[:, 0, 1], P[:, 2, 2] + R[:, 1, 1])
    return gaussian_loglik2(d2, det)


def sequence_score(
    times: np.ndarray,
    z: np.ndarray,
    R: np.ndarray,
    has: np.ndarray,
    kappa: np.ndarray,
    *,
    p_detection: float,
    new_target_density: float,
    miss_dl: float,
    v_max: float,
    motion: MotionModel,
) -> tuple[np.ndarray, np.ndarray]:
    """Score ``L`` and running peak of plot sequences, as an every-plot tree would score
    the branch (module docstring), with ``motion``'s filter and plot likelihood.

    ``times`` (N,) scan times, or (n, N) per sequence (timed plots: each plot's own time,
    a miss at its slot's nominal time); per sequence and scan ``z`` (n, N, 2), ``R`` (n, N, 2, 2),
    ``has`` (n, N) plot present, ``kappa`` (n, N) clutter intensity at the plot. Every
    sequence needs at least one plot.
    """
    n, N = has.shape
    r = motion.n_models
    st = States(np.zeros((n, 4)), np.zeros((n, 4, 4)), np.zeros((n, r, 4)),
                np.zeros((n, r, 4, 4)), np.ones((n, r)))
    L, peak = np.zeros(n), np.full(n, -np.inf)
    started = np.zeros(n, bool)
    for s in range(N):
        if s and started.any():
            dt = (float(times[s] - times[s - 1]) if times.ndim == 1
                  else times[started, s] - times[started, s - 1])
            st.put(started, motion.predict(st.take(started), dt))
        h = has[:, s]
        new = h & ~started
        if new.any():
            st.put(new, motion.new_states(*one_point_state(z[new, s], R[new, s], v_max)))
            L[new] = birth_score(kappa[new, s], p_detection, new_target_density)
        upd = h & started
        if upd.any():
            zu, Ru = z[upd, s], R[upd, s]
            pred = st.take(upd)
            k = np.arange(len(zu))
            ll = motion.gating_loglik(pred, k, k, zu, Ru, innovation_loglik(pred, zu, Ru))
            L[upd] += update_increment(ll, kappa[upd, s], p_detection, new_target_density)
            st.put(upd, motion.update(pred, zu, Ru))
        L[started & ~h] += miss_dl
        started |= new
        peak = np.where(started, np.maximum(peak, L), peak)
    return L, peak


def score_upper_bound(
    has: np.ndarray,
    R: np.ndarray,
    kappa: np.ndarray,
    *,
    p_detection: float,
    new_target_density: float,
    miss_dl: float,
) -> np.ndarray:
    """An upper bound of :func:`sequence_score` without any Kalman step: the innovation
    covariance ``S = HPHᵀ + R`` has ``det S ≥ det R`` and ``d² ≥ 0`` (for each IMM model,
    hence for their mixture), so an update adds at
    most ``ln P_D − ln(κ̂ + λ_v) − ln 2π − ½ ln det R``. Sequences whose bound is below the
    birth floor cannot pass it and are dropped before they are scored."""
    n, N = has.shape
    first = np.argmax(has, axis=1)
    after = np.arange(N)[None, :] > first[:, None]
    up = (np.log(p_detection) - np.log(kappa + new_target_density) - LOG_2PI
          - 0.5 * np.log(det2(R)))
    L0 = birth_score(kappa[np.arange(n), first], p_detection, new_target_density)
    return L0 + np.where(after & has, up, 0.0).sum(axis=1) + miss_dl * (after & ~has).sum(axis=1)
