"""Merge and split of Gaussian components held as moment statistics
(:mod:`mhtrack.clutter.moments`), the structural moves of the forgetting mixture
(:mod:`mhtrack.clutter.forgetting`) as its clumps drift, meet and part.

* *merge*: two components whose means are closer than ``distance`` (Mahalanobis, under
  their mean covariance) are one: their statistics add, which is the moment-preserving
  merge (Salmond 1990; Runnalls, IEEE TAES 43(3), 2007);
* *split*: a component whose kurtosis along its principal axis is below ``kurtosis``
  (a Gaussian has 3; two clumps drifting apart, well below 2) becomes two Gaussians at
  ``μ ± ½√λ₁ v`` with the principal variance reduced to keep the second moment
  (the split moves of Ueda et al., "SMEM algorithm for mixture models", 2000).

Each component is anchored at its mean (:func:`reanchor`).
"""

from __future__ import annotations

import numpy as np

from mhtrack.clutter.moments import gaussian_moments, mean_cov, principal_kurtosis, shift
from mhtrack.models.linalg2 import sym_mahalanobis2

_SPLIT_OFFSET = 0.5  # children at μ ± ½√λ₁ v


def reanchor(m: np.ndarray, anchors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The statistics ``m`` (K, 15) moved to each component's mean, and those means."""
    if not len(m):
        return m, anchors
    _, means, _ = mean_cov(m, anchors, 0.0)
    return shift(m, means - anchors), means


def merge(m: np.ndarray, anchors: np.ndarray, reg_covar: float, distance: float
          ) -> tuple[np.ndarray, np.ndarray]:
    """Merge the closest pair while it is closer than ``distance`` (module docstring)."""
    while len(m) > 1:
        _, means, cov = mean_cov(m, anchors, reg_covar)
        k = len(means)
        i, j = np.triu_indices(k, 1)
        d = means[i] - means[j]
        s = 0.5 * (cov[i] + cov[j])
        d2, _ = sym_mahalanobis2(d[:, 0], d[:, 1], s[:, 0, 0], s[:, 0, 1], s[:, 1, 1])
        best = int(np.argmin(d2))
        if d2[best] >= distance**2:
            break
        a, b = int(i[best]), int(j[best])
        m = m.copy()
        m[a] += shift(m[b:b + 1], anchors[a:a + 1] - anchors[b:b + 1])[0]
        keep = np.ones(k, bool)
        keep[b] = False
        m, anchors = reanchor(m[keep], anchors[keep])
    return m, anchors


def split(m: np.ndarray, anchors: np.ndarray, room: int, min_points: float,
          kurtosis: float) -> tuple[np.ndarray, np.ndarray]:
    """Split up to ``room`` components (flattest first) whose principal kurtosis is below
    ``kurtosis`` and whose weight is at least ``2·min_points`` (module docstring)."""
    if kurtosis <= 0 or not len(m):
        return m, anchors
    w, means, cov = mean_cov(m, anchors, 0.0)
    v, lam, beta = principal_kurtosis(m, cov)
    cand = np.flatnonzero((beta < kurtosis) & (w >= 2 * min_points) & (lam > 0))
    cand = cand[np.argsort(beta[cand], kind="stable")][:max(room, 0)]
    if not cand.size:
        return m, anchors
    off = _SPLIT_OFFSET * np.sqrt(lam[cand])[:, None] * v[cand]
    child = cov[cand] - (off[:, :, None] * off[:, None, :])
    cm = gaussian_moments(0.5 * w[cand], child)
    m, anchors = m.copy(), anchors.copy()
    m[cand] = cm
    anchors[cand] = means[cand] + off
    return np.vstack([m, cm]), np.vstack([anchors, means[cand] - off])
