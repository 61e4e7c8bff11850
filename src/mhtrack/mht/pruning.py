"""Hypothesis management: SPRT deletion, score-drop pruning, N-scan pruning and hard caps.

Every function takes arrays of leaves sorted by tree id and returns a boolean *keep*
mask; the caps also return how many leaves (or trees) they removed, so the tracker can
report every time a cap acts.
"""

from __future__ import annotations

import numpy as np

from mhtrack.mht.tree import NO_PLOT, segment_ids, segment_max, segment_starts


def sprt_keep(score: np.ndarray, peak: np.ndarray, delete_threshold: float) -> np.ndarray:
    """Wald's SPRT deletion applied as a score drop: keep a leaf while
    ``L − L_peak > ln(β/(1−α))`` (Blackman & Popoli 1999 §6.2). For a tentative leaf whose
    score never rose, ``L_peak`` is its birth score, so this is Wald's test on the evidence
    gathered since birth; for a confirmed track it detects the target's disappearance."""
    return score - peak > delete_threshold


def tentative_keep(score: np.ndarray, tentative: np.ndarray, delete_threshold: float) -> np.ndarray:
    """Wald's lower SPRT threshold on the score itself for tentative (unconfirmed) leaves:
    keep unless ``tentative`` and ``L ≤ ln(β/(1−α))`` (Blackman & Popoli 1999 §6.2 delete
    tentative tracks on the absolute threshold, confirmed ones on the drop from the peak).
    In dense clutter a tree born with ``L₀ = ln(λ_v P_D/(κ̂ + λ_v))`` far below the threshold is
    then never grown, instead of branching for four scans until its drop reaches it."""
    return ~(tentative & (score <= delete_threshold))


def score_drop_keep(tree: np.ndarray, score: np.ndarray, drop: float) -> np.ndarray:
    """Keep leaves no more than ``drop`` below the best leaf of their tree."""
    starts, seg = segment_ids(tree)
    return score >= segment_max(score, starts, seg) - drop


def _rank_in_tree(tree: np.ndarray, score: np.ndarray) -> np.ndarray:
    """Rank (0 = best) of each leaf within its tree by score, ties by index.

    One stable argsort of the key ``segment + (max − score)/(range + 1)``: cheaper than a
    two-key lexsort; scores closer than ~1e−11 of their range count as ties."""
    n = score.size
    starts, seg = segment_ids(tree)
    hi = float(score.max())
    u = (hi - score) / (hi - float(score.min()) + 1.0)
    order = np.argsort(seg + u, kind="stable")
    rank = np.empty(n, np.int64)
    rank[order] = np.arange(n) - starts[seg[order]]
    return rank


def cap_leaves_per_tree(tree: np.ndarray, score: np.ndarray, cap: int) -> tuple[np.ndarray, int]:
    """Keep each tree's ``cap`` best leaves (ties: lower index). Returns (keep, removed)."""
    starts = segment_starts(tree)
    if np.diff(np.r_[starts, score.size]).max(initial=0) <= cap:
        return np.ones(score.size, bool), 0
    keep = _rank_in_tree(tree, score) < cap
    return keep, int(score.size - keep.sum())


def _top(priority_keys: tuple[np.ndarray, ...], cap: int) -> np.ndarray:
    """Boolean mask of the first ``cap`` rows in lexicographic order of ``priority_keys``
    (last key primary, as ``np.lexsort``), ties by index."""
    n = priority_keys[0].size
    keep = np.zeros(n, bool)
    keep[np.lexsort(priority_keys)[:cap]] = True  # lexsort is stable
    return keep


def cap_leaves(
    score: np.ndarray, confirmed: np.ndarray, cap: int
) -> tuple[np.ndarray, int]:
    """Keep at most ``cap`` leaves: confirmed trees' leaves first, then highest scores."""
    if score.size <= cap:
        return np.ones(score.size, bool), 0
    return _top((-score, ~confirmed), cap), int(score.size - cap)


def cap_trees(
    tree: np.ndarray, score: np.ndarray, protected: np.ndarray, cap: int
) -> tuple[np.ndarray, int]:
    """Keep the leaves of at most ``cap`` trees: trees with a ``protected`` leaf (in the best
    hypothesis or confirmed) first, then by best-leaf score, then lower tree id.
    Returns (keep mask over leaves, trees removed)."""
    starts, seg = segment_ids(tree)
    if starts.size <= cap:
        return np.ones(tree.size, bool), 0
    best = np.maximum.reduceat(score, starts)
    prot = np.maximum.reduceat(protected.astype(np.int8), starts) > 0
    keep_tree = _top((tree[starts], -best, ~prot), cap)
    return keep_tree[seg], int(starts.size - cap)


def n_scan_keep(tree: np.ndarray, oldest: np.ndarray, chosen: np.ndarray) -> np.ndarray:
    """N-scan pruning (P1 §1.3; Blackman & Popoli 1999 §16.3.4).

    ``oldest`` (L,) is each leaf's plot at scan ``k − N`` (window column 0), ``chosen`` the
    leaf indices of the best global hypothesis. A leaf is kept unless

    * its tree is in the best hypothesis and its plot at ``k − N`` differs from that of
      the chosen leaf (the decision at ``k − N`` is made), or
    * its plot at ``k − N`` is used by the best hypothesis in another tree.

    Trees not in the best hypothesis keep their other leaves.
    """
    n = tree.size
    keep = np.ones(n, bool)
    if chosen.size == 0 or n == 0:
        return keep
    ctree, cplot = tree[chosen], oldest[chosen]
    # rule 1: same tree as a chosen leaf, different plot at k − N
    i = np.searchsorted(ctree, tree)  # chosen leaves are ascending, hence sorted by tree
    i = np.minimum(i, ctree.size - 1)
    in_hyp = ctree[i] == tree
    keep &= ~(in_hyp & (oldest != cplot[i]))
    # rule 2: plot at k − N taken by the best hypothesis in another tree
    used = cplot != NO_PLOT
    if used.any():
        up, ut = cplot[used], ctree[used]
        o = np.argsort(up, kind="stable")
        up, ut = up[o], ut[o]
        j = np.minimum(np.searchsorted(up, oldest), up.size - 1)
        taken = (up[j] == oldest) & (oldest != NO_PLOT)
        keep &= ~(taken & (ut[j] != tree))
    return keep
