"""Clustering: trees that share a plot (directly or through a chain of trees) form a
cluster; the global hypothesis splits into one independent problem per cluster
(P1 §1.3; Blackman & Popoli 1999 §16.3).

Two leaves *conflict* when they belong to the same tree or use the same plot at the same
scan. A plot is identified by ``(window column, plot id)``, so plot ids need only be
unique within a scan — when every tree steps every scan (P1's scans). With frames of
several sensors a tree's columns are its *own* looks (``docs/mht.md``, *Asynchronous
plots*): the same plot may sit in column 1 of one tree and column 0 of another, so there
(``by_id``) a plot is identified by its id alone, ids unique over the window (a
:class:`~mhtrack.records.PlotTable`'s rows are).
"""

from __future__ import annotations

import numpy as np

from mhtrack.kernels import changes
from mhtrack.mht.tree import NO_PLOT


def plot_keys(window: np.ndarray, *, by_id: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Flatten the plots used in ``window`` (L, W) to ``(leaf, key)`` pairs with one
    integer key per distinct ``(column, plot id)`` (``by_id``: per distinct plot id),
    misses left out. Keys are dense ``0 … K−1`` in sorted ``(column, plot)`` (``plot``)
    order."""
    leaf, raw = raw_plot_keys(window, by_id=by_id)
    if leaf.size == 0:
        return leaf, raw
    _, key = np.unique(raw, return_inverse=True)
    return leaf, key.reshape(-1).astype(np.int64)


def raw_plot_keys(window: np.ndarray, *, by_id: bool = False) -> tuple[np.ndarray,
                                                                       np.ndarray]:
    """As :func:`plot_keys`, with keys not made dense: ``column·span + plot`` (``by_id``:
    the plot id). Same order and same equalities as the dense keys (one a strictly
    increasing function of the other), one sort less."""
    leaf, col = np.nonzero(window != NO_PLOT)
    if leaf.size == 0:
        e = np.zeros(0, np.int64)
        return e, e
    plot = window[leaf, col]
    leaf = leaf.astype(np.int64, copy=False)  # no copy when already int64 (nonzero's)
    if by_id:
        return leaf, plot.astype(np.int64)
    span = int(plot.max()) + 1
    return leaf, col.astype(np.int64, copy=False) * span + plot


def dense_index(tree: np.ndarray) -> np.ndarray:
    """``np.unique(tree, return_inverse=True)[1]`` (int64), by one pass when ``tree`` is
    already sorted (leaves are kept sorted by tree), else by ``np.unique``."""
    if tree.size > 1 and np.count_nonzero(tree[1:] < tree[:-1]) == 0:
        index = changes(tree).cumsum()
        index -= 1
        return index
    return np.unique(tree, return_inverse=True)[1].reshape(-1).astype(np.int64)


def cluster_trees(tree: np.ndarray, window: np.ndarray, *,
                  by_id: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Connected components of the graph whose nodes are trees and plots and whose edges
    join a tree to each plot one of its leaves uses.

    Parameters
    ----------
    tree : (L,) tree id of each leaf.
    window : (L, W) plot ids per scan of each leaf (``-1``: none).
    by_id : a plot is its id, whatever its column (:func:`plot_keys`).

    Returns
    -------
    tree_index : (L,) index of each leaf's tree in ``np.unique(tree)``.
    tree_cluster : (T,) cluster label of each unique tree; labels are ``0 … C−1``
        numbered in order of each cluster's smallest tree id (deterministic).
    """
    tree_index = dense_index(tree)
    leaf, raw = raw_plot_keys(window, by_id=by_id)
    return tree_index, tree_clusters(tree_index, leaf, raw)


def tree_clusters(tree_index: np.ndarray, leaf: np.ndarray, key: np.ndarray) -> np.ndarray:
    """The ``tree_cluster`` of :func:`cluster_trees` from its parts: each leaf's tree
    index (dense, ``0 … T−1``) and the leaves' ``(leaf, key)`` plot pairs
    (:func:`raw_plot_keys` or :func:`plot_keys`)."""
    n_trees = int(tree_index.max()) + 1 if tree_index.size else 0
    if leaf.size == 0:
        return np.arange(n_trees, dtype=np.int64)
    label = _min_label_components(tree_index[leaf], key, n_trees)
    if label is not None:
        # every tree is labelled with the smallest tree of its cluster: the clusters in
        # order of their smallest tree are the labels in increasing order
        rank = (label == np.arange(n_trees)).cumsum()
        rank -= 1
        return rank[label]
    # pathological chain: let scipy do it
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    _, dense = np.unique(key, return_inverse=True)
    dense = dense.reshape(-1)
    n_keys = int(dense.max()) + 1
    n = n_trees + n_keys
    graph = coo_matrix(
        (np.ones(leaf.size, np.int8), (tree_index[leaf], n_trees + dense)), shape=(n, n)
    )
    label = connected_components(graph, directed=False)[1][:n_trees]
    # number clusters by their smallest tree (first appearance in tree order)
    _, first, inv = np.unique(label, return_index=True, return_inverse=True)
    rank = np.empty(first.size, np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(first.size)
    return rank[inv.reshape(-1)]


def _min_label_components(
    tree: np.ndarray, key: np.ndarray, n_trees: int, max_iter: int = 64
) -> np.ndarray | None:
    """Connected components of the bipartite tree–plot graph with edges ``(tree, key)``
    (any integer keys: only their equalities count) by min-label propagation with pointer
    jumping: every tree ends labelled with the smallest tree index of its component.
    ``None`` if not converged in ``max_iter``."""
    by_key = np.lexsort((tree, key))
    k_sorted, t_by_key = key[by_key], tree[by_key]
    k_new = changes(k_sorted)
    k_starts = k_new.nonzero()[0]
    k_of_edge = k_new.cumsum()
    k_of_edge -= 1
    by_tree = t_by_key.argsort(kind="stable")
    t_sorted = t_by_key[by_tree]
    t_starts = changes(t_sorted).nonzero()[0]
    t_ids = t_sorted[t_starts]
    label = np.arange(n_trees, dtype=np.int64)
    for _ in range(max_iter):
        key_min = np.minimum.reduceat(label[t_by_key], k_starts)
        tree_min = np.minimum.reduceat(key_min[k_of_edge][by_tree], t_starts)
        new = label.copy()
        new[t_ids] = np.minimum(label[t_ids], tree_min)
        new = new[new]  # pointer jumping: label[i] <= i always
        if np.count_nonzero(new != label) == 0:
            return label
        label = new
    return None
