"""The exact branch-and-bound of the global hypothesis on small clusters
(:func:`~mhtrack.mht.hypothesis.best_hypothesis`), all the clashing clusters of a scan
prepared together.

A cluster's problem (P1 §1.3; Blackman & Popoli 1999 §16.3): choose for every tree one of
its leaves or none, no two chosen leaves using the same plot, the largest total score.
:func:`search` is a depth-first branch-and-bound over trees — best tree first, within a
tree best leaf first and "none" last; the bound of a node is its running total plus every
remaining tree's best score; a greedy incumbent first. It returns the *first* solution, in
that depth-first order, whose running total beats every earlier one, so the choice among
equal totals is fixed (ties: lower leaf index). :func:`search_two` is the same search
unrolled for the commonest cluster, two trees (:func:`mhtrack.kernels.two_tree_search`),
with the same sums and comparisons in the same order: the same choice, without the stack.

:func:`solve_small` builds every clashing cluster's options from one sort and one set of
plot keys.
"""

from __future__ import annotations

import itertools

import numpy as np

from mhtrack.kernels import changes, two_tree_search

#: One tree's options, best first: ``(score, plot mask, leaf)``.
Option = tuple[float, int, int]


def solve_small(
    s: np.ndarray, tree_index: np.ndarray, keys: tuple[np.ndarray, np.ndarray],
    leaf_cluster: np.ndarray, in_small: np.ndarray, node_limit: int,
) -> tuple[np.ndarray, list[np.ndarray]]:
    """:func:`search` on every cluster ``c`` with ``in_small[c]`` (candidate leaves:
    scores ``s`` > 0, trees ``tree_index``, plot keys ``keys`` = ``(leaf, key)`` of
    :func:`~mhtrack.mht.clustering.raw_plot_keys`, clusters ``leaf_cluster``).
    Plot masks: bit = the plot's rank among its cluster's keys (any one-to-one numbering
    gives the same conflicts). Returns the chosen leaves and the members of each cluster
    whose search passed ``node_limit`` (for ``milp``)."""
    member = in_small[leaf_cluster]
    idx = member.nonzero()[0]
    lc = leaf_cluster[idx]
    on = member[keys[0]]
    position = member.cumsum()
    position -= 1
    leaf, raw = position[keys[0][on]], keys[1][on]  # leaf: position in idx
    c = lc[leaf]
    by_key = np.lexsort((raw, c))
    c, raw, leaf = c[by_key], raw[by_key], leaf[by_key]
    first = changes(c)
    dense = (first | changes(raw)).cumsum()
    local = dense - np.maximum.accumulate(np.where(first, dense, 1))
    low = local < 63
    m = np.zeros(idx.size, np.uint64)
    np.bitwise_or.at(m, leaf[low], np.left_shift(np.uint64(1), local[low].astype(np.uint64)))
    ti, si = tree_index[idx], s[idx]
    order = np.lexsort((-si, ti, lc))  # cluster, tree, best first; ties: index (stable)
    t_start = changes(ti[order]).nonzero()[0]  # a cluster's trees are consecutive
    c_start = [*changes(lc[order][t_start]).nonzero()[0].tolist(), t_start.size]
    ordered = order.tolist()
    if np.count_nonzero(low) == low.size:
        masks = m.take(order).tolist()  # in the options' order
    else:  # bits past 62: Python integers
        by_leaf = m.tolist()
        for i, k in zip(leaf[~low].tolist(), local[~low].tolist(), strict=True):
            by_leaf[i] |= 1 << k
        masks = [by_leaf[j] for j in ordered]
    rows = list(zip(si.take(order).tolist(), masks, ordered, strict=True))
    bounds = [*t_start.tolist(), order.size]
    trees = [rows[a:b] for a, b in itertools.pairwise(bounds)]
    limited, picks = [], []
    for a, b in itertools.pairwise(c_start):
        options = trees[a:b]
        best = search_two(options, node_limit) if b - a == 2 else search(options, node_limit)
        if best is None:
            limited.append(np.sort(idx[[i for o in options for _, _, i in o]]))
        else:
            picks.extend(best)
    return idx[np.asarray(picks, np.int64)], limited


def search(options: list[list[Option]], node_limit: int) -> list[int] | None:
    """Branch-and-bound over trees; ``options[t]``: tree ``t``'s ``(score, plot mask,
    leaf)``, best first (ties: lower leaf). The chosen leaves, or ``None`` after
    ``node_limit`` nodes."""
    options.sort(key=lambda opts: (-opts[0][0], opts[0][2]))
    bound = [0.0] * (len(options) + 1)
    for t in range(len(options) - 1, -1, -1):
        bound[t] = bound[t + 1] + options[t][0][0]
    # greedy incumbent: a lower bound that prunes early
    best_val, best_sel, used = 0.0, [], 0
    for opts in options:
        for sc, m, i in opts:
            if not m & used:
                used |= m
                best_val += sc
                best_sel.append(i)
                break
    nodes, n_trees = 0, len(options)
    stack: list[tuple[int, int, float, tuple[int, ...]]] = [(0, 0, 0.0, ())]
    while stack:
        t, used, val, sel = stack.pop()
        nodes += 1
        if nodes > node_limit:
            return None
        if val + bound[t] <= best_val:
            continue
        if t == n_trees:
            best_val, best_sel = val, list(sel)
            continue
        # push in reverse so that the best leaf is explored first, "leave out" last
        stack.append((t + 1, used, val, sel))
        for sc, m, i in reversed(options[t]):
            if not m & used:
                stack.append((t + 1, used | m, val + sc, (*sel, i)))
    return best_sel


def search_two(options: list[list[Option]], node_limit: int) -> list[int] | None:
    """:func:`search` on two trees: :func:`mhtrack.kernels.two_tree_search` (the same
    search unrolled: the same nodes in the same order, the same sums and comparisons,
    hence the same choice) when it cannot pass ``node_limit``; else :func:`search`,
    which then decides (``None`` exactly when the search passes it)."""
    a_opts, b_opts = options
    if (-b_opts[0][0], b_opts[0][2]) < (-a_opts[0][0], a_opts[0][2]):
        a_opts, b_opts = b_opts, a_opts  # search's order: best tree first
    p, q = len(a_opts), len(b_opts)
    if 1 + (p + 1) * (q + 2) > node_limit:  # nodes: root, A's p + 1, each's q + 1
        return search(options, node_limit)
    return two_tree_search(a_opts, b_opts)
