"""Reference solver of the global hypothesis, for tests only: exhaustive enumeration."""

from __future__ import annotations

import itertools

import numpy as np


def brute_force_best_hypothesis(
    score: np.ndarray, tree: np.ndarray, window: np.ndarray
) -> tuple[np.ndarray, float]:
    """Enumerate every choice of one leaf or none per tree.

    Returns the chosen indices (ascending) and the total; exponential in the number of
    trees — small problems only. Among equal totals the first in enumeration order wins.
    """
    score = np.asarray(score, float)
    tree = np.asarray(tree)
    window = np.asarray(window)
    uniq = sorted(set(tree.tolist()))
    per_tree = [[None, *np.flatnonzero(tree == t).tolist()] for t in uniq]
    best_total, best_sel = 0.0, ()
    for combo in itertools.product(*per_tree):
        sel = tuple(i for i in combo if i is not None)
        used = [(c, p) for i in sel for c, p in enumerate(window[i].tolist()) if p >= 0]
        if len(used) != len(set(used)):
            continue
        total = float(sum(score[i] for i in sel))
        if total > best_total:
            best_total, best_sel = total, sel
    return np.sort(np.asarray(best_sel, np.int64)), best_total
