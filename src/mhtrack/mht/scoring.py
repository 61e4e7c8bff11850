"""Track score: the log-likelihood ratio of a track hypothesis against all-clutter.

``L(k) = L(k−1) + ΔL(k)`` (P1 eq. 4) with (P1 eqs. 5, 15)::

    ΔL = ln(1 − P_D)                                  on a miss
    ΔL = ln[ p(z|T) · P_D / (κ̂(z) + λ_v) ]            on an update with plot z

``p(z|T)`` is the Kalman innovation likelihood ``N(ν; 0, S)``, ``κ̂(z)`` the clutter
intensity from the clutter estimator and ``λ_v`` the new-target density. A tree born from
plot ``z`` starts at ``L₀ = ln(λ_v · P_D / (κ̂(z) + λ_v))`` (:func:`birth_score`).
Track management is Wald's sequential probability ratio test on that score
(:mod:`mhtrack.mht.sprt`).
"""

from __future__ import annotations

import math

import numpy as np


def miss_increment(p_detection: float, gate_probability: float | None = None) -> float:
    """Score increment of a missed detection.

    ``ΔL = ln(1 − P_D)`` (P1 eq. 5). With ``gate_probability`` ``P_G`` given, the exact
    form ``ln(1 − P_D·P_G)``: the target may have been detected outside the gate
    (Blackman & Popoli 1999 §6.2; Bar-Shalom et al. 2009, PDAF miss term).
    """
    pg = 1.0 if gate_probability is None else gate_probability
    return math.log1p(-p_detection * pg)


def miss_increments(p_detection: np.ndarray, gate_probability: float | None = None
                    ) -> np.ndarray:
    """:func:`miss_increment` per leaf, each with its own ``P_D`` (the frame's sensor's
    coverage, :mod:`mhtrack.mht.coverage`); ``P_D = 0`` (not looked at) gives 0. Computed
    once per distinct ``P_D`` with :func:`miss_increment`, so a constant ``P_D`` gives
    exactly the scalar increment."""
    pd = np.asarray(p_detection, float)
    if pd.size and (pd == pd.flat[0]).all():  # one P_D (every leaf looked at alike)
        return np.full(pd.shape, miss_increment(float(pd.flat[0]), gate_probability))
    if pd.size == 0:
        return np.zeros(0)
    lo, hi = pd.min(), pd.max()
    low = pd == lo
    if (low | (pd == hi)).all():  # two values (a sensor's P_D and 0, typically)
        return np.where(low, miss_increment(float(lo), gate_probability),
                        miss_increment(float(hi), gate_probability)).reshape(-1)
    values = np.unique(pd)  # sorted; the increment of each, then per leaf by its P_D
    inc = np.array([miss_increment(float(v), gate_probability) for v in values], float)
    return inc.take(np.searchsorted(values, pd.reshape(-1)))


def update_increment(
    loglik: np.ndarray, kappa: np.ndarray, p_detection: float | np.ndarray,
    new_target_density: float, plot: np.ndarray | None = None,
) -> np.ndarray:
    """Score increment of updating with a plot, P1 eqs. 5 / 15:
    ``ΔL = ln p(z|T) + ln P_D − ln(κ̂(z) + λ_v)``, with ``loglik = ln p(z|T)``. ``kappa``
    per pair, or per plot with ``plot`` each pair's plot: the plot's part
    ``ln P_D − ln(κ̂ + λ_v)`` is then computed once per plot (the same floats).
    ``p_detection`` one value, or one per plot like ``kappa`` (the ``P_D`` of each
    plot's type, :meth:`~mhtrack.mht.coverage.Coverage.plot_pds`)."""
    lpd = math.log(p_detection) if isinstance(p_detection, float) else np.log(p_detection)
    per = lpd - np.log(kappa + new_target_density)
    return loglik + (per if plot is None else per.take(plot))


def birth_score(kappa: np.ndarray, p_detection: float, new_target_density: float) -> np.ndarray:
    """Initial score of a tree started by plot ``z``: the likelihood ratio of a new target
    against the reference of P1 eq. 15, ``L₀ = ln(λ_v · P_D / (κ̂(z) + λ_v))``.

    Blackman & Popoli (1999 §6.2) start a track at ``LR(1) = P_D β_NT / β_FT`` (new-target
    density ``β_NT = λ_v``, false-target density ``β_FT = κ̂``) and *continue* it with
    ``P_D g / β_FT``. P1 eq. 15 continues it with ``P_D g / (κ̂ + λ_v)``: a plot not on the
    track is clutter *or* a new target. A birth score must use the same denominator, or a
    plot's two explanations are not comparable in the global hypothesis: with ``β_FT``
    alone, "track missed + new tree on the plot" beats "track updated" as soon as
    ``λ_v (1 − P_D)/κ̂ > g/(κ̂ + λ_v)`` — for every plot when ``κ̂ ≪ λ_v`` (tracks then coast
    beside their own plots). With the shared denominator the update wins iff
    ``g > λ_v (1 − P_D)``, whatever ``κ̂``. ``L₀ ≤ ln P_D``: a lone plot never confirms."""
    return math.log(new_target_density * p_detection) - np.log(kappa + new_target_density)
