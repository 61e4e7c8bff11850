"""Hypothesis management: score-drop pruning, N-scan pruning and hard caps, and the
pruning stages of the tracker (:func:`prune_children`; after the solve
:func:`kept_after_solve` then :func:`take_kept`, composed in :func:`prune_after_solve`).

Every rule takes arrays of leaves sorted by tree id and returns a boolean *keep* mask; the
caps also return how many leaves (or trees) they removed, so the tracker can report every
time a cap acts (SPRT deletion: :mod:`mhtrack.mht.sprt`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mhtrack.kernels import changes, segment_sizes
from mhtrack.mht.caps import CHILDREN_PER_PLOT, MISSES_PER_TREE
from mhtrack.mht.carry import Merged
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.context import FrameContext
from mhtrack.mht.extend import Children
from mhtrack.mht.frame_scope import Scope
from mhtrack.mht.hypothesis import GlobalHypothesis
from mhtrack.mht.merging import merge_keep
from mhtrack.mht.sprt import SPRT
from mhtrack.mht.tree import (
    NO_PLOT,
    Leaves,
    segment_ids,
    segment_starts,
    take_deferred,
)


def score_drop_keep(tree: np.ndarray, score: np.ndarray, drop: float) -> np.ndarray:
    """Keep leaves no more than ``drop`` below the best leaf of their tree."""
    if score.size == 0:
        return np.ones(0, bool)
    starts = segment_starts(tree)
    best = np.maximum.reduceat(score, starts)  # each tree's, repeated over its rows
    return score >= np.repeat(best, segment_sizes(starts, score.size)) - drop


def _rank_in_groups(group: np.ndarray, score: np.ndarray,
                    span: tuple[float, float] | None = None) -> np.ndarray:
    """Rank (0 = best) of each row within its group (integers ≥ 0, in any order) by
    score, ties by index.

    One stable argsort of the key ``group + (max − score)/(range + 1)``: cheaper than a
    two-key lexsort; scores closer than ~1e−11 of their range count as ties. ``span``:
    the ``(max, min)`` to use instead of the scores' own — those of a larger set whose
    whole groups these rows are, which then get the ranks (and ties) they have in it."""
    n = score.size
    hi, lo = (float(score.max()), float(score.min())) if span is None else span
    u = (hi - score) / (hi - lo + 1.0)
    order = np.argsort(group + u, kind="stable")
    starts = segment_starts(group[order])
    rank = np.empty(n, np.int64)
    rank[order] = np.arange(n) - np.repeat(starts, segment_sizes(starts, n))
    return rank


def _largest_tree(tree: np.ndarray) -> int:
    """Rows of the largest tree (``tree`` sorted; 0 for no rows)."""
    return int(segment_sizes(segment_starts(tree), tree.size).max(initial=0))


def cap_leaves_per_tree(tree: np.ndarray, score: np.ndarray, cap: int) -> tuple[np.ndarray, int]:
    """Keep each tree's ``cap`` best leaves (ties: lower index). Returns (keep, removed).

    Only the trees over the cap are ranked, with the key of all of them
    (:func:`_rank_in_groups`' ``span``, the same segment numbers): the same ranks, ties
    included, as ranking every leaf."""
    starts = segment_starts(tree)
    size = segment_sizes(starts, tree.size)
    if size.max(initial=0) <= cap:
        return np.ones(score.size, bool), 0
    big = size > cap
    over = np.repeat(big, size).nonzero()[0]  # the rows of the trees over the cap
    rank = _rank_in_groups(np.repeat(big.nonzero()[0], size[big]), score.take(over),
                           (float(score.max()), float(score.min())))
    keep = np.ones(score.size, bool)
    keep[over[rank >= cap]] = False
    return keep, int(score.size - np.count_nonzero(keep))


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


def n_scan_keep(tree: np.ndarray, oldest: np.ndarray, chosen: np.ndarray,
                window: np.ndarray | None = None, defer: np.ndarray | None = None
                ) -> np.ndarray:
    """N-scan pruning (P1 §1.3; Blackman & Popoli 1999 §16.3.4).

    ``oldest`` (L,) is each leaf's plot at scan ``k − N`` (window column 0), ``chosen`` the
    leaf indices of the best global hypothesis. A leaf is kept unless

    * its tree is in the best hypothesis and its plot at ``k − N`` differs from that of
      the chosen leaf (the decision at ``k − N`` is made), or
    * its plot at ``k − N`` is used by the best hypothesis in another tree.

    Trees not in the best hypothesis keep their other leaves, and so do the leaves
    marked in ``defer`` (L,) (``MHTConfig.defer_tentative``: the tentative trees' —
    rule 1 waits until the tree is confirmed, a larger N for them alone; rule 2 still
    holds).

    ``window`` (L, W), frames of several sensors (each tree's columns are its own looks):
    rule 2 holds for the chosen leaves' plots at their own ``k − N`` found in *any*
    column of another tree's leaf — that tree may have looked fewer times, so the plot
    sits in a later column; kept, the leaf would turn compatible (a duplicate of the
    track) once the plot leaves the track's window. And the other way, a leaf's own
    plot at its ``k − N`` found in any column of a chosen leaf of another tree (the leaf
    looked more often, and would forget the conflict at its next look). With scans
    (every tree steps every scan) both reduce to rule 2.
    """
    n = tree.size
    if chosen.size == 0 or n == 0:
        return np.ones(n, bool)
    ctree, cplot = tree[chosen], oldest[chosen]
    # rule 1: same tree as a chosen leaf, different plot at k − N
    i = ctree.searchsorted(tree)  # chosen leaves are ascending, hence sorted by tree
    np.minimum(i, ctree.size - 1, out=i)
    drop = (ctree[i] == tree) & (oldest != cplot[i])
    if defer is not None:
        drop &= ~defer
    # rule 2: plot at k − N taken by the best hypothesis in another tree
    used = cplot != NO_PLOT
    if np.count_nonzero(used):
        up, ut = cplot[used], ctree[used]
        o = up.argsort(kind="stable")
        up, ut = up[o], ut[o]
        if window is None:
            drop |= _taken(up, ut, oldest, tree)
        else:
            drop |= _taken(up, ut, window, tree[:, None]).any(axis=1)
    if window is not None:  # rule 2, the other way: the leaf's own k − N anywhere
        cw = window[chosen]
        row, col = np.nonzero(cw != NO_PLOT)
        if row.size:
            up, ut = cw[row, col], ctree[row]
            o = up.argsort(kind="stable")
            drop |= _taken(up[o], ut[o], oldest, tree)
    return ~drop


def _taken(up: np.ndarray, ut: np.ndarray, cols: np.ndarray, tree: np.ndarray) -> np.ndarray:
    """Mask like ``cols`` ((L,) or (L, C)): the plot is one of the sorted ``up`` whose
    tree ``ut`` differs from the leaf's ``tree`` (broadcast against ``cols``)."""
    j = up.searchsorted(cols)
    np.minimum(j, up.size - 1, out=j)
    return (up[j] == cols) & (cols != NO_PLOT) & (ut[j] != tree)


def prune_children(frame: FrameContext, leaves: Leaves, children: Children, sprt: SPRT, *,
                   n_births: int) -> Children:
    """Before the (costly) Kalman update: SPRT deletion, score-drop pruning within a
    tree, the overload rule (``frame.scene_leaves``: the leaves the scan supports,
    :func:`mhtrack.mht.caps.scene_leaves`; ``None``: off), then the caps on leaves per
    tree and on all leaves of the frame's limits (``n_births`` of ``max_leaves`` and of
    ``scene_leaves`` are kept for this scan's new trees). What a cap cuts goes to the
    frame's counters."""
    cfg, scene_leaves = frame.limits, frame.scene_leaves
    rows = sprt.keep(children.score, children.peak,
                     leaves.track.take(children.parent) < 0).nonzero()[0]
    tree = leaves.tree.take(children.parent.take(rows))
    keep = score_drop_keep(tree, children.score.take(rows), cfg.prune_drop)
    children, tree = children.take(rows[keep]), tree[keep]  # one copy of the children
    if scene_leaves is not None and leaf_caps_act(tree, max(cfg.max_leaves - n_births, 0),
                                                  cfg.max_leaves_per_tree):
        if tree.size > scene_leaves - n_births:  # over the scene's budget: every tree
            keep, cut = cap_per_plot(tree, children.plot, children.score)
            name = "max_leaves_per_plot"
        else:  # within it: the tentative trees only
            keep, cut = cap_per_plot(tree, children.plot, children.score,
                                     among=leaves.track[children.parent] < 0)
            name = "max_tentative_per_plot"
        if cut:
            frame.cut(name, cut)
            children, tree = children.take(keep), tree[keep]
    keep, cut = cap_leaves_per_tree(tree, children.score, cfg.max_leaves_per_tree)
    if cut:
        frame.cut("max_leaves_per_tree", cut)
        children, tree = children.take(keep), tree[keep]
    budget = max(cfg.max_leaves - n_births, 0)
    confirmed = leaves.track.take(children.parent) >= 0
    keep, cut = cap_leaves(children.score, confirmed, budget)
    if cut:
        frame.cut("max_leaves", cut)
        children = children.take(keep)
    return children


def leaf_caps_act(tree: np.ndarray, budget: int, per_tree: int) -> bool:
    """Whether the leaf caps would cut these children (sorted by ``tree``): more than
    ``budget`` in all, or more than ``per_tree`` in one tree."""
    return tree.size > budget or _largest_tree(tree) > per_tree


def cap_per_plot(tree: np.ndarray, plot: np.ndarray, score: np.ndarray,
                 per_plot: int = CHILDREN_PER_PLOT,
                 per_tree_miss: int = MISSES_PER_TREE,
                 among: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """The overload rule (``mhtrack.mht.caps``): keep the ``per_plot`` best children of
    each plot over all trees and the ``per_tree_miss`` best miss children of each tree
    (ties: lower index; :func:`_rank_in_groups`). Returns (keep, removed); at most
    ``per_plot · plots + per_tree_miss · trees`` children are kept. ``among`` (mask):
    the rule ranks and cuts these children only, as if given them alone; the others
    are kept."""
    if among is not None:
        sub = among.nonzero()[0]
        keep = np.ones(score.size, bool)
        k, cut = cap_per_plot(tree.take(sub), plot.take(sub), score.take(sub), per_plot,
                              per_tree_miss)
        keep[sub[~k]] = False
        return keep, cut
    if score.size == 0:
        return np.ones(0, bool), 0
    upd = plot >= 0
    key = np.where(upd, plot, -1 - tree)  # misses grouped by tree, apart from the plots
    rank = _rank_in_groups(key - key.min(), score)
    keep = rank < np.where(upd, per_plot, per_tree_miss)
    return keep, int(score.size - np.count_nonzero(keep))


def removed_after_solve(leaves: Leaves, hyp: GlobalHypothesis,
                        cfg: MHTConfig) -> np.ndarray | None:
    """Leaves the optional rules remove after the solve (``None``: both off).

    * probability pruning (``cfg.prune_probability > 0``): leaves with a positive score
      whose probability over the N best hypotheses (``hyp.probability``) is below it;
    * merging (``cfg.merge_frames > 0``): all but one of each group of duplicate branches
      (:func:`~mhtrack.mht.merging.merge_keep`).

    Leaves of the best hypothesis are never removed."""
    if cfg.prune_probability <= 0 and cfg.merge_frames <= 0:
        return None
    chosen = np.zeros(len(leaves), bool)
    chosen[hyp.leaves] = True
    remove = np.zeros(len(leaves), bool)
    if cfg.prune_probability > 0:
        remove |= (leaves.score > 0) & (hyp.probability < cfg.prune_probability)
    if cfg.merge_frames > 0:
        remove |= ~merge_keep(leaves.window, chosen, leaves.track >= 0, leaves.score,
                              cfg.merge_frames)
    return remove & ~chosen


def prune_after_solve(frame: FrameContext, leaves: Leaves, chosen: np.ndarray, *,
                      by_id: bool = False, remove: np.ndarray | None = None,
                      parts: tuple[Leaves, Leaves] | Merged | None = None,
                      scope: Scope | None = None) -> Leaves:
    """N-scan pruning around the best hypothesis (leaf indices ``chosen``), then the cap
    on trees (the frame's ``max_trees``, counted in its caps); marks the surviving chosen
    leaves: :func:`kept_after_solve` then :func:`take_kept` (the tracker calls the two
    itself, to hand the kept rows to the frame scope; this composition is the one-call
    form for library users and tests)."""
    kept = kept_after_solve(frame, leaves, chosen, by_id=by_id, remove=remove, scope=scope)
    return take_kept(leaves, kept, chosen, parts)


def kept_after_solve(frame: FrameContext, leaves: Leaves, chosen: np.ndarray, *,
                     by_id: bool = False, remove: np.ndarray | None = None,
                     scope: Scope | None = None) -> np.ndarray | None:
    """The rows of ``leaves`` N-scan pruning around the best hypothesis (leaf indices
    ``chosen``) and then the cap on trees (the frame's ``max_trees``, counted in its
    caps) keep, ascending (``None``: all). ``by_id``: trees step on their own looks
    (:func:`n_scan_keep`'s ``window``). ``remove``: a mask of further leaves to drop
    (:func:`removed_after_solve`). ``scope``: N-scan pruning looks at these rows only,
    the others are kept (:mod:`mhtrack.mht.frame_scope`: the groups a frame touched; the
    same keep mask)."""
    max_trees = frame.limits.max_trees
    n = len(leaves)
    tentative = leaves.track < 0 if frame.limits.defer_tentative else None
    if scope is None or scope.rows is None:
        keep = n_scan_keep(leaves.tree, leaves.window[:, 0], chosen,
                           leaves.window if by_id else None, tentative)
    else:
        w = leaves.window.take(scope.rows, axis=0)
        keep = np.ones(n, bool)
        keep[scope.rows] = n_scan_keep(
            leaves.tree.take(scope.rows), w[:, 0], scope.chosen, w if by_id else None,
            None if tentative is None else tentative.take(scope.rows))
    if remove is not None:
        keep &= ~remove
    n_kept = int(np.count_nonzero(keep))
    if n_kept > max_trees:  # else at most max_trees trees (each has a leaf): no cut
        kept = keep.nonzero()[0]
        tree = leaves.tree.take(kept)
        if np.count_nonzero(changes(tree)) > max_trees:  # the trees kept
            protected = leaves.track >= 0
            protected[chosen] = True
            keep_t, cut = cap_trees(tree, leaves.score.take(kept), protected.take(kept),
                                    max_trees)
            frame.cut("max_trees", cut)
            keep[kept[~keep_t]] = False
            n_kept = int(np.count_nonzero(keep))
    return None if n_kept == n else keep.nonzero()[0]  # None: nothing pruned


def take_kept(leaves: Leaves, rows: np.ndarray | None, chosen: np.ndarray,
              parts: tuple[Leaves, Leaves] | Merged | None = None) -> Leaves:
    """Rows ``rows`` of ``leaves`` (:func:`kept_after_solve`; ``None``: all) with the
    chosen leaves (indices ``chosen`` into ``leaves``) marked. ``parts``: ``leaves``
    defers its states, copied once here for the rows kept — from the two stores it
    concatenates (:func:`~mhtrack.mht.tree.take_deferred`) or from the grown, new and
    carried leaves it merges (:meth:`~mhtrack.mht.carry.Merged.take`)."""
    is_chosen = np.zeros(len(leaves), bool)
    is_chosen[chosen] = True
    mark = is_chosen if rows is None else is_chosen[rows]
    if isinstance(parts, Merged):
        return parts.take(leaves, rows, chosen=mark)
    if parts is not None:
        return take_deferred(leaves, rows, parts, chosen=mark)
    if rows is None:  # the same arrays
        return replace(leaves, chosen=is_chosen)
    return replace(leaves.take(rows), chosen=mark)
