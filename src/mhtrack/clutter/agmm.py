"""MHT-AGMM's clutter estimator: the adaptive GMM of P1 §2 (eqs. 6–14).

EM starts with ``K`` components, more than the clutter has (P1 step 1). After every
M-step, P1 step c (eq. 12) keeps the ``M`` largest-weight components whose weights sum
above 0.92 — the fewest such — and renormalises their weights (the Lagrange condition of
eq. 12: maximising the likelihood over the weights of the ``M`` kept components subject to
``Σ π̂_m = 1`` rescales them by their sum). EM stops when ``|ΔL| < ε|L|`` (P1 step 3).
The intensity is ``κ̂(z) = M̂_k ĉ(z)`` (eq. 14) with ``M̂_k`` the Poisson ML clutter count
(:mod:`mhtrack.clutter.mixture`).

P1 cites Zivkovic (2004) for the adaptive choice of the number of components; Zivkovic's
rule shrinks every weight by a Dirichlet-prior constant and drops those that reach 0.
We implement P1's rule as printed (eq. 12), not Zivkovic's.

P1 derives its component count from "a Lagrange inequality of the model parameters and the
number of components" [10]: the price of a component grows with its parameters. Eq. 12
alone has no such price, so the adaptive GMM here also deletes, after each M-step, a
Gaussian whose removal costs the fit less than the BIC price of its six parameters
(``bic=True``, :func:`mhtrack.clutter.em.removal_gain`). The fixed-threshold GMM
(:mod:`mhtrack.clutter.gmm`) has no test of the number of components, as P1 describes it.

P1 step 1 initialises means and covariances with "random numbers in 1–100", which makes no
sense in metres on an 8 km region (every mean would start in one corner 100 m wide); we
seed the means by k-means++ among the plots from a seeded generator instead
(:func:`mhtrack.clutter.seeding.kmeanspp_centres`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.clutter.em import PruneRule
from mhtrack.clutter.mixture import MixtureClutter

#: P1 eq. 12's empirical mass threshold.
P1_MASS = 0.92


def keep_mass(weights: np.ndarray, mass: float = P1_MASS) -> np.ndarray:
    """P1 eq. 12: mask of the fewest largest-weight components whose weights sum above
    ``mass`` (ties broken by index). E.g. ``[0.5, 0.3, 0.15, 0.05]`` → the first three
    (0.95 > 0.92 while 0.8 ≤ 0.92). All are kept when no prefix exceeds ``mass``."""
    w = np.asarray(weights, dtype=float)
    keep = np.zeros(w.size, bool)
    if w.size == 0:
        return keep
    order = (-w).argsort(kind="stable")
    m, csum = w.size, 0.0
    for i, v in enumerate(w[order].tolist()):  # np.cumsum's additions, in its order
        csum += v
        if csum > mass:
            m = i + 1
            break
    keep[order[:m]] = True
    return keep


class AGMMClutter(MixtureClutter):
    """Adaptive-GMM clutter intensity ``κ̂(z) = M̂_k ĉ(z)`` (MHT-AGMM, P1 §2).

    Parameters
    ----------
    n_components : ``K`` to start from, more than the truth. Default 8 (P1 Table 2 has 4).
    mass : eq. 12's threshold. Default 0.92 (P1).
    bic : the BIC test of the number of components (module docstring). Default True.
    **kwargs : the shared parameters of :class:`~mhtrack.clutter.mixture.MixtureClutter`
        (``source``, ``window`` 5, ``background``, ``tol`` ε = 1e−4, ...).
    """

    name = "agmm"

    def __init__(
        self, n_components: int = 8, *, mass: float = P1_MASS, bic: bool = True, **kwargs: Any
    ) -> None:
        if not (np.isfinite(mass) and 0.0 < mass < 1.0):
            raise ValueError(f"mass must be in (0, 1), got {mass!r}")
        self.mass = float(mass)
        super().__init__(n_components, bic=bic, **kwargs)

    def _prune_rule(self) -> PruneRule:
        m = self.mass
        return lambda w: keep_mass(w, m)
