"""MHT-GMM's clutter estimator: EM with a fixed component-deletion threshold (P1 §2).

P1 describes the "traditional" GMM clutter-density estimator it compares against as EM
(eqs. 6–11) in which components whose weight falls under a fixed deletion threshold are
removed to keep the cost down; P1 gives no value. Ours: after every M-step, delete the
Gaussians whose weight, normalised over the Gaussians, is below ``threshold`` (default
0.05), then renormalise. Everything else (window, warm start, background, count ``M̂_k``)
is :class:`~mhtrack.clutter.mixture.MixtureClutter`'s, identical to the AGMM's, so that the
two differ only in how they choose the number of components: a fixed weight threshold here
(P1: "a fixed deletion threshold ... to lower the cost"), eq. 12 and a BIC test of each
component there (:mod:`mhtrack.clutter.agmm`). ``bic=True`` gives the GMM that test too.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.clutter.em import PruneRule
from mhtrack.clutter.mixture import MixtureClutter


def keep_above(weights: np.ndarray, threshold: float) -> np.ndarray:
    """Mask of the components with ``π_j ≥ threshold`` (MHT-GMM's fixed deletion rule);
    the largest component is always kept."""
    w = np.asarray(weights, dtype=float)
    keep = w >= threshold
    if w.size and not keep.any():
        keep[int(np.argmax(w))] = True
    return keep


class GMMClutter(MixtureClutter):
    """``κ̂(z) = M̂_k ĉ(z)`` with ``ĉ`` an EM-fitted GMM whose components under a fixed
    weight ``threshold`` are deleted (MHT-GMM, P1 §2–3).

    Parameters
    ----------
    threshold : deletion threshold on the Gaussians' normalised weights. Default 0.05
        (ours; P1 gives none).
    bic : also the AGMM's BIC test of each component. Default False (P1's fixed-threshold
        GMM).
    **kwargs : the shared parameters of :class:`~mhtrack.clutter.mixture.MixtureClutter`
        (``n_components`` 8, ``source``, ``window`` 5, ``background``, ...).
    """

    name = "gmm"

    def __init__(self, n_components: int = 8, *, threshold: float = 0.05, **kwargs: Any) -> None:
        if not (np.isfinite(threshold) and 0.0 <= threshold < 1.0):
            raise ValueError(f"threshold must be in [0, 1), got {threshold!r}")
        self.threshold = float(threshold)
        super().__init__(n_components, **kwargs)

    def _prune_rule(self) -> PruneRule:
        t = self.threshold
        return lambda w: keep_above(w, t)
