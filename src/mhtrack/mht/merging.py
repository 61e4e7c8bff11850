"""Merging duplicate branches: leaves that followed the same plots over the last frames.

Two leaves whose last ``M`` window columns hold the same plots and misses (at least one a
plot) will score the same from now on and differ only in their older past; keeping both
doubles the work and, across trees, lets two tracks follow one target
(Blackman & Popoli 1999 §16.3.5, "track merging"). Of each such group the first by
(in the best hypothesis, confirmed, higher score, lower index) is kept.
"""

from __future__ import annotations

import numpy as np

from mhtrack.mht.tree import NO_PLOT


def merge_keep(window: np.ndarray, chosen: np.ndarray, confirmed: np.ndarray,
               score: np.ndarray, frames: int) -> np.ndarray:
    """Keep mask over leaves: one leaf per group of equal last-``frames`` windows.

    Parameters
    ----------
    window : (L, W) plot ids per window column (``-1``: miss).
    chosen, confirmed : (L,) bool, in the best hypothesis / of a confirmed tree.
    score : (L,) leaf scores.
    frames : ``M``, the columns compared (the last ``M``); 0 keeps every leaf.
    """
    n = window.shape[0]
    keep = np.ones(n, bool)
    if frames <= 0 or n == 0:
        return keep
    last = np.ascontiguousarray(window[:, -frames:])
    has_plot = (last != NO_PLOT).any(axis=1)
    idx = np.flatnonzero(has_plot)
    if idx.size < 2:
        return keep
    _, group = np.unique(last[idx], axis=0, return_inverse=True)
    group = group.reshape(-1)
    # priority: chosen, confirmed, higher score, lower index (lexsort: last key primary)
    order = np.lexsort((idx, -score[idx], ~confirmed[idx], ~chosen[idx], group))
    first = np.r_[True, group[order][1:] != group[order][:-1]]
    keep[idx[order[~first]]] = False
    return keep
