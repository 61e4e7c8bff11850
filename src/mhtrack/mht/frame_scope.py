"""The frame's scope: the best global hypothesis and N-scan pruning solved again only for
the groups of trees a frame touched (issue 30, national load).

A frame of one radar's sector steps a few per cent of the trees; the others are carried
unchanged (:func:`~mhtrack.mht.timed.split_looked`). The global hypothesis splits into
independent clusters (:mod:`mhtrack.mht.clustering`), and a cluster's solution depends
only on its own leaves (scores, trees, windows, in store order): solving a cluster alone
or among all gives the same leaves (:func:`~mhtrack.mht.hypothesis.best_hypothesis`).

*Groups.* The connected components of the graph of trees joined by a plot any of their
leaves use — over **all** leaves, not only the positive-score ones the solve takes, so
that N-scan pruning's rule 2 (a leaf dropped for a plot the best hypothesis uses in
another tree) never reaches out of a group. A group is *clean* at a frame when its
trees' leaves are exactly those it had when it was last solved and that solve's pruning
removed none of them: its solution (the leaves marked ``chosen``) and pruning (keep all)
would come out the same again. The scope of a frame is every other group: the trees the
frame stepped or started, the groups that held a tree now stepped or gone, the groups
whose leaves the last pruning cut (N-scan or the cap on trees), the groups solved with a
cap acting (``max_cluster_size``, ``milp_node_limit``: counted at every frame, as a full
solve counts them), and every clean group sharing a plot with a leaf of these (one round
suffices: two clean groups share no plot, having been components when solved). The
groups of the scope are found again after its solve; the others keep theirs.

The result — chosen leaves, pruning and the step's statistics (clusters, largest
cluster, the caps' counts) — is the full solve's, row for row
(``tests/mht/test_frame_scope.py``); only the work differs. Used with per-tree looks
(:attr:`~mhtrack.mht.coverage.Coverage.per_tree_looks`), one best hypothesis and
neither probability pruning, merging nor ``defer_tentative``; otherwise, and after a
restart (nothing cached), every leaf is in the scope. ``defer_tentative`` is left out
because confirmation runs after :meth:`FrameScope.pruned` has marked the groups clean: a
tree confirmed at frame ``k`` and not stepped at ``k + 1`` would be skipped there, where
the full solve prunes it with N-scan's rule 1 now applying to it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mhtrack.kernels import segment_sizes
from mhtrack.mht.clustering import dense_index, raw_plot_keys, tree_clusters
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.context import FrameContext
from mhtrack.mht.hypothesis import GlobalHypothesis, best_hypothesis
from mhtrack.mht.tree import NO_PLOT, Leaves, contains, segment_starts


@dataclass(frozen=True, slots=True)
class _Groups:
    """The trees of the store after a frame (sorted ids) and their group (dense ids),
    with each group's clusters of positive leaves (count, largest) and whether it must
    be solved again (``dirty``). A group whose solve counted a cap is always dirty, so
    the clean ones count none."""

    tree: np.ndarray
    group: np.ndarray
    n_clusters: np.ndarray
    largest: np.ndarray
    dirty: np.ndarray


@dataclass(frozen=True, slots=True)
class Scope:
    """A frame's scope: the store's leaves solved (ascending rows, ``None``: all) and
    the chosen ones among them (positions in ``rows``)."""

    rows: np.ndarray | None
    chosen: np.ndarray


class FrameScope:
    """The solve stage of :class:`~mhtrack.mht.tracker.MHTTracker` over the groups a frame
    touched (module docstring). ``enabled`` false: every leaf at every frame (the full
    solve; the tests compare the two)."""

    def __init__(self, config: MHTConfig, by_id: bool) -> None:
        self.config, self.by_id = config, by_id
        self.enabled = True
        self._groups: _Groups | None = None
        self._pending: _Groups | None = None

    @property
    def applies(self) -> bool:
        """Whether the configuration allows a scope smaller than the store."""
        cfg = self.config
        return (self.enabled and self.by_id and cfg.n_best == 1
                and cfg.prune_probability <= 0 and cfg.merge_frames <= 0
                and not cfg.defer_tentative)

    def solve(self, frame: FrameContext, leaves: Leaves, first_node: int,
              ) -> tuple[GlobalHypothesis, Scope]:
        """The best global hypothesis over ``leaves`` (the store after the frame's births;
        leaves with ``node ≥ first_node`` are new) and the scope pruning takes; clusters
        solved greedily or stopped by the node limit count as caps in ``frame``. Its
        ``leaves``, ``total`` (summed over the chosen leaves in store order, as the full
        solve sums), ``probability``, ``n_clusters`` and ``largest_cluster`` are the full
        solve's; with a scope smaller than the store, ``n_searched``, ``n_greedy`` and
        ``n_node_limited`` count the scope's clusters only, and ``leaf_cluster`` and
        ``cut_clusters`` are empty (nothing downstream reads them)."""
        self._pending = None
        idle = leaves.node < first_node
        if not self.applies or not idle.any():
            self._groups = None  # every tree stepped: nothing to carry
            hyp = self._best(leaves.score, leaves.tree, leaves.window)
            self._count(frame, hyp.n_greedy, hyp.n_node_limited)
            return hyp, Scope(None, hyp.leaves)
        starts = segment_starts(leaves.tree)
        size = segment_sizes(starts, len(leaves))
        tree = leaves.tree.take(starts)
        old = self._groups
        found = None if old is None else _scope_trees(leaves, old, tree, starts, size, idle)
        if found is None:  # nothing cached (first frame, a restart): all
            group, dirty_tree = np.zeros(tree.size, np.int64), np.ones(tree.size, bool)
        else:
            group, dirty_tree = found
        in_scope = np.repeat(dirty_tree, size)
        rows = None if dirty_tree.all() else in_scope.nonzero()[0]
        # the columns the solve reads, of the scope's rows only
        score, tree_s, window = (leaves.score, leaves.tree, leaves.window) if rows is None \
            else (leaves.score.take(rows), leaves.tree.take(rows), leaves.window.take(rows, 0))
        hyp = self._best(score, tree_s, window)
        local = hyp.leaves
        # the scope's groups (components over all its leaves) and their clusters
        t_index = dense_index(tree_s)
        g_new = tree_clusters(t_index, *raw_plot_keys(window, by_id=True))
        n_g = int(g_new.max()) + 1 if g_new.size else 0
        on = (hyp.leaf_cluster >= 0).nonzero()[0]
        cl = hyp.leaf_cluster[on]
        first = np.unique(cl, return_index=True)[1]  # clusters are 0 … C−1
        of_cluster = g_new[t_index[on[first]]]
        n_cl = np.bincount(of_cluster, minlength=n_g)
        largest = np.zeros(n_g, np.int64)
        np.maximum.at(largest, of_cluster, np.bincount(cl))
        capped = np.zeros(n_g, bool)  # solved again at every frame, counted each time
        capped[of_cluster[hyp.cut_clusters]] = True
        n_clusters, big = hyp.n_clusters, hyp.largest_cluster
        chosen = local if rows is None else rows[local]
        clean_g = np.zeros(0, np.int64)
        if rows is not None:  # the clean groups: as solved before
            assert old is not None
            clean_g = _present(group[~dirty_tree], old.dirty.size).nonzero()[0]
            n_clusters += int(old.n_clusters[clean_g].sum())
            big = max(big, int(old.largest[clean_g].max(initial=0)))
            is_chosen = leaves.chosen & ~in_scope
            is_chosen[chosen] = True
            chosen = is_chosen.nonzero()[0]
        self._count(frame, hyp.n_greedy, hyp.n_node_limited)
        # the store's trees: clean groups numbered first (as ranked), the scope's after
        tree_group = np.empty(tree.size, np.int64)
        rank = np.zeros(old.dirty.size if old is not None else 0, np.int64)
        rank[clean_g] = np.arange(clean_g.size)  # a table, not a binary search
        tree_group[~dirty_tree] = rank[group[~dirty_tree]]
        tree_group[dirty_tree] = clean_g.size + g_new
        if old is None or rows is None:
            self._pending = _Groups(tree, tree_group, n_cl, largest, capped)
        else:
            self._pending = _Groups(
                tree, tree_group, np.concatenate((old.n_clusters[clean_g], n_cl)),
                np.concatenate((old.largest[clean_g], largest)),
                np.concatenate((np.zeros(clean_g.size, bool), capped)))
        probability = np.zeros(len(leaves))
        probability[chosen] = 1.0
        hyp = replace(hyp, leaves=chosen, total=float(leaves.score[chosen].sum()),
                      n_clusters=n_clusters, largest_cluster=big,
                      probability=probability, leaf_cluster=np.zeros(0, np.int64),
                      cut_clusters=np.zeros(0, np.int64))
        return hyp, Scope(rows, local)

    def pruned(self, before: Leaves, after: Leaves, kept: np.ndarray | None = None) -> None:
        """After pruning ``before`` to ``after`` (``kept``: the rows of ``before`` kept,
        ascending, when known; ``None``: found from the node ids): the groups of the trees
        kept; those that lost leaves (N-scan or the cap on trees) are solved again at the
        next frame."""
        pend, self._pending = self._pending, None
        if pend is None:
            return
        dirty = pend.dirty
        if len(after) < len(before):
            if kept is None:
                lost = ~contains(after.node, before.node)  # node ids span the run
            else:
                lost = np.ones(len(before), bool)
                lost[kept] = False
            leaf_group = np.repeat(pend.group, segment_sizes(segment_starts(before.tree),
                                                             len(before)))
            dirty = dirty.copy()
            dirty[leaf_group[lost]] = True
        a_tree = after.tree.take(segment_starts(after.tree))
        g = pend.group[np.searchsorted(pend.tree, a_tree)]
        present = _present(g, dirty.size)
        used = present.nonzero()[0]
        rank = present.cumsum()
        rank -= 1
        self._groups = _Groups(a_tree, rank[g], pend.n_clusters[used], pend.largest[used],
                               dirty[used])

    # ------------------------------------------------------------------ helpers
    def _best(self, score: np.ndarray, tree: np.ndarray, window: np.ndarray
              ) -> GlobalHypothesis:
        cfg = self.config
        return best_hypothesis(score, tree, window, cfg.max_cluster_size,
                               cfg.milp_node_limit, by_id=self.by_id, n_best=cfg.n_best)

    @staticmethod
    def _count(frame: FrameContext, n_greedy: int, n_limited: int) -> None:
        if n_greedy:
            frame.cut("max_cluster_size", n_greedy)
        if n_limited:
            frame.cut("milp_node_limit", n_limited)


def _present(ids: np.ndarray, n: int) -> np.ndarray:
    """Mask over ``0 … n−1``: the ids that occur in ``ids`` (a sort-free ``np.unique``)."""
    mask = np.zeros(n, bool)
    mask[ids] = True
    return mask


def _scope_trees(leaves: Leaves, old: _Groups, tree: np.ndarray, starts: np.ndarray,
                 size: np.ndarray, idle: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Each store tree's group at the last frame and whether it is in the scope (module
    docstring); ``None`` when the store's carried trees are not the cached ones."""
    carried = idle.take(starts)  # a tree is stepped whole or carried whole
    if old.tree.size == 0:
        return None
    j = np.minimum(np.searchsorted(old.tree, tree), old.tree.size - 1)
    if not (old.tree[j[carried]] == tree[carried]).all():
        return None
    gdirty = old.dirty.copy()
    kept = tree[carried]  # both sorted: a binary search, no sort
    k = np.minimum(np.searchsorted(kept, old.tree), max(kept.size - 1, 0))
    gone = np.ones(old.tree.size, bool) if kept.size == 0 else kept[k] != old.tree
    gdirty[old.group[gone]] = True  # stepped or gone
    group = np.where(carried, old.group[j], 0)
    dirty_tree = ~carried | gdirty[group]
    # clean groups sharing a plot with a leaf of the scope join it (one round)
    in_scope = np.repeat(dirty_tree, size)
    w = leaves.window
    plots = w[in_scope].ravel()
    plots = plots[plots != NO_PLOT]
    if plots.size and not in_scope.all():
        hit = _uses(w, plots) & ~in_scope
        if hit.any():
            gdirty[np.repeat(group, size)[hit]] = True
            dirty_tree = ~carried | gdirty[group]
    return group, dirty_tree


def _uses(window: np.ndarray, plots: np.ndarray) -> np.ndarray:
    """Mask over the rows of ``window`` (L, W): the row holds one of ``plots`` (ids ≥ 0).
    A table over the plots' span when it is small against the window (ids outside it
    read a ``False`` cell), else ``np.isin``."""
    lo, hi = int(plots.min()), int(plots.max())
    span = hi - lo + 1
    if span > 4 * window.size + 1024:
        return np.isin(window, plots).any(axis=1)
    table = np.zeros(span + 1, bool)  # the last cell: every id outside the span
    table[plots - lo] = True
    at = window - lo
    at[(at < 0) | (at >= span)] = span
    return table[at].any(axis=1)
