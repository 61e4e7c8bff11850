"""Track probabilities from the N best global hypotheses of a cluster.

A global hypothesis ``h`` with score ``S_h`` (sum of its leaves' log-likelihood ratios)
has posterior probability ``P(h) ∝ exp(S_h)`` (Reid 1979; Blackman & Popoli 1999
§16.3.3). Over the N best hypotheses ``H_N`` of the cluster, normalised::

    P(h) = exp(S_h − S_max) / Σ_{g ∈ H_N} exp(S_g − S_max)
    P(leaf) = Σ_{h ∈ H_N, leaf ∈ h} P(h)

A leaf in none of the N best gets 0; a tree's probability of being a target is the sum
over its leaves (:func:`tree_probabilities`). With N = 1 the chosen leaves get 1.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np


def hypothesis_probabilities(totals: Sequence[float]) -> np.ndarray:
    """``P(h)`` of each hypothesis from its score ``S_h`` (softmax, max subtracted)."""
    t = np.asarray(totals, float)
    if t.size == 0:
        return t
    w = np.exp(t - t.max())
    return w / math.fsum(w.tolist())


def leaf_probabilities(ranked: Sequence[tuple[tuple[int, ...], float]],
                       n_leaves: int) -> np.ndarray:
    """``P(leaf)`` for leaves ``0 … n_leaves−1`` from ``[(leaf indices, S_h), …]``."""
    p = np.zeros(n_leaves)
    for (leaves, _), ph in zip(ranked, hypothesis_probabilities([t for _, t in ranked]),
                               strict=True):
        p[list(leaves)] += ph
    return np.minimum(p, 1.0)


def tree_probabilities(tree: np.ndarray, probability: np.ndarray) -> dict[int, float]:
    """Probability that each tree (track) is a target: the sum of its leaves'."""
    out: dict[int, float] = {}
    for t, p in zip(np.asarray(tree).tolist(), np.asarray(probability).tolist(), strict=True):
        out[t] = out.get(t, 0.0) + p
    return out
