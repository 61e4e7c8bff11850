"""Empirical-Bayes shrinkage of relative rates toward 1: how much a clutter map's counts
are allowed to correct a parametric start, estimated from the counts' over-dispersion.

Cell ``c`` holds ``S_c`` plots against ``E_c`` expected by the start (discounted sums over
rotations, :mod:`mhtrack.clutter.calibrated`). The Poisson–gamma model of Clayton &
Kaldor ("Empirical Bayes estimates of age-standardized relative risks for use in disease
mapping", *Biometrics* 43(3), 1987): ``S_c | r_c ~ Poisson(r_c E_c)``, ``r_c ~ Gamma(b, b)``
(mean 1: the start is trusted on average, Hjort & Glad 1995; variance ``v = 1/b``), whose
posterior mean is ``r̂_c = (S_c + b) / (E_c + b)``. A discounted sum of Poisson counts has
the variance ``φ`` times its mean, ``φ = Σ_m γ^{2m} / Σ_m γ^m`` (the map's forgetting,
:func:`~mhtrack.clutter.radar_map.forgetting_variance_factor`): in units of ``φ`` plots
(quasi-Poisson) the posterior mean is ``r̂_c = (S_c + φ b) / (E_c + φ b)``.

``v`` is estimated by the method of moments over the cells (Clayton & Kaldor §3; the
weighted form of Marshall, *Appl. Statist.* 40(2), 1991), with the prior mean held at 1:
``E (S_c − E_c)² = φ E_c + v E_c²`` and ``E S_c = E_c`` give

    v̂ = Σ_c [(S_c − E_c)² − φ S_c] / Σ_c E_c²,

kept only when the counts are over-dispersed against Poisson(``E``) by Dean & Lawless's
score test ("Tests for detecting overdispersion in Poisson regression models", *JASA*
84(406), 1989: ``T = Σ_c [(S_c − E_c)² − φ S_c] / (φ √(2 Σ_c E_c²))``, one-sided at
:data:`Z_OVERDISPERSED`), else ``v̂ = 0``: ``b = ∞``, every ratio 1, the start unchanged.
"""

from __future__ import annotations

import numpy as np

#: One-sided 5 % point of N(0, 1): the over-dispersion test's threshold on ``T``.
Z_OVERDISPERSED = 1.6448536269514722


def prior_count(s: np.ndarray, e: np.ndarray, phi: float = 1.0) -> float:
    """``φ b̂ = φ / v̂`` (plots; ``inf`` when the counts are not over-dispersed) from the
    observed ``s`` and expected ``e`` counts per cell (module docstring)."""
    s, e = np.asarray(s, float).reshape(-1), np.asarray(e, float).reshape(-1)
    e2 = float(np.dot(e, e))
    if not (e2 > 0 and phi > 0):
        return np.inf
    excess = float(np.sum((s - e) ** 2 - phi * s))
    if not excess > Z_OVERDISPERSED * phi * np.sqrt(2.0 * e2):
        return np.inf
    return phi * e2 / excess


def shrunk_ratio(s: np.ndarray, e: np.ndarray, b: float) -> np.ndarray:
    """``(s + b) / (e + b)`` per cell, 1 where ``b`` is infinite (no over-dispersion)."""
    if not np.isfinite(b):
        return np.ones(np.shape(s))
    return (np.asarray(s, float) + b) / (np.asarray(e, float) + b)
