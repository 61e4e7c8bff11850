"""Pairwise-distance searches of the clustering without all-pairs matrices (bounded
memory in bursts).

Adaptive K-means (:mod:`mhtrack.initiation.kmeans`) reads order statistics of the pairwise
distances ``D`` (P2 §1.2 steps 1–3): ``ε(k)`` reads ``D`` at index ``k·C(N_s, 2) − 1``,
and ``k`` never exceeds the number of plots ``n``, so only the ``n·C(N_s, 2)`` smallest of
the ``C(n, 2)`` distances are ever read — and with the threshold cap, only those below
it. Written directly, ``D`` of 100 000 plots would take 37 GiB. :class:`SortedDistances`
finds the part read with a k-d tree (``cKDTree.count_neighbors`` to choose a search
radius ``r`` holding at least that many pairs, ``query_pairs(r)`` to list them): memory
O(n · neighbours within ``r``). The distances are computed with the arithmetic of
``scipy.spatial.distance.pdist`` (``√(dx² + dy²)``, the same bits). :func:`close_pairs`
lists the pairs of centres within a radius, chunk by chunk in a burst (the merge of
compatible clusters). Small scans keep the dense code (:data:`DENSE_PAIRS`). The
assignment of plots to centres is :mod:`mhtrack.initiation.assignment`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from scipy.spatial import cKDTree

#: Up to this many pairs ``C(n, 2)`` the distances are all computed (``pdist``, 8 MiB).
DENSE_PAIRS = 1 << 20
#: At most ``max(PAIR_BUDGET_FACTOR · need, DENSE_PAIRS)`` pairs are listed at once.
PAIR_BUDGET_FACTOR = 8
#: :func:`close_pairs` lists pairs at once up to ``max(DENSE_PAIRS, PAIRS_PER_POINT · n)``.
PAIRS_PER_POINT = 16


def pair_distances(z: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """``‖z_i − z_j‖ = √(dx² + dy²)``, the arithmetic of ``pdist`` (same bits)."""
    d = z[i] - z[j]
    return np.sqrt((d**2).sum(-1))


def _sorted_unique(a: np.ndarray) -> np.ndarray:
    """``np.unique(a)`` by one sort (faster than its hash table on millions of keys)."""
    a = np.sort(a)
    return a[np.r_[True, a[1:] != a[:-1]]] if a.size else a


def _pairs_within(tree: cKDTree, r: float) -> int:
    """Number of pairs ``i < j`` with ``‖z_i − z_j‖ ≤ r`` (k-d tree count, no listing)."""
    return (int(tree.count_neighbors(tree, r)) - tree.n) // 2


class SortedDistances:
    """``D``: the ``C(n, 2)`` pairwise distances of ``z`` (n, 2) sorted ascending (P2 §1.2
    step 2), of which only the part that will be read is computed.

    ``D[i]`` is exact for ``i < need``; with a ``cap``, every distance ``≤ cap`` is exact
    and a distance above it may read as ``+inf`` (a caller takes ``min(D[i], cap)``). Beyond
    that, indexing raises ``IndexError``. ``len(D) = C(n, 2)``.

    Up to :data:`DENSE_PAIRS` pairs (or when ``need`` reaches ``C(n, 2)``) ``D`` is
    ``np.sort(pdist(z))``. Otherwise a radius ``r`` is chosen such that between ``need``
    and ``max(8·need, DENSE_PAIRS)`` pairs lie within it (a k-nearest-neighbour bound, then
    bisection on ``cKDTree.count_neighbors``), and only those pairs are listed. Distances
    that tie exactly over more pairs than that budget (e.g. thousands of plots on one
    point) are read as the tie's value as the k-d tree computes it.
    """

    def __init__(self, z: np.ndarray, need: int, cap: float | None = None) -> None:
        from scipy.spatial.distance import pdist
        z = np.asarray(z, float).reshape(-1, 2)
        n = len(z)
        self._len = n * (n - 1) // 2
        need = min(max(int(need), 0), self._len)
        self.need = need
        self._fill_value, self._fill_end = np.inf, 0
        self._above_cap = False  # past the computed part every distance is > cap
        if self._len <= DENSE_PAIRS or need >= self._len:
            self._head = np.sort(pdist(z))
            return
        if need == 0:
            self._head = np.zeros(0)
            return
        self._sparse(z, need, cap)

    def _sparse(self, z: np.ndarray, need: int, cap: float | None) -> None:
        from scipy.spatial import cKDTree
        tree = cKDTree(z)
        budget = max(PAIR_BUDGET_FACTOR * need, DENSE_PAIRS)
        hi = _knn_bound(tree, z, need)
        if cap is not None and cap < hi:
            hi, self._above_cap = float(cap), True
        count = _pairs_within(tree, hi)
        if count <= budget:
            self._listed(tree, z, hi, need)
            self._above_cap &= count < need
            return
        lo = 0.0
        c_lo = _pairs_within(tree, lo)
        if c_lo >= need:  # ≥ need pairs of coincident plots: the smallest need are 0
            self._head, self._above_cap = np.zeros(need), False
            return
        for _ in range(200):  # bisection: need ≤ count(r) ≤ budget, or an exact tie
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                break
            c = _pairs_within(tree, mid)
            if need <= c <= budget:
                self._listed(tree, z, mid, need)
                self._above_cap = False
                return
            if c < need:
                lo, c_lo = mid, c
            else:
                hi, count = mid, c
        # ties: every pair in (lo, hi] has one distance, the value hi
        self._listed(tree, z, lo, need, margin=False)
        self._fill_value, self._fill_end = float(hi), min(count, self._len)
        self._above_cap = False

    def _listed(self, tree: cKDTree, z: np.ndarray, r: float, need: int, *,
                margin: bool = True) -> None:
        """The smallest ``need`` distances among the pairs within ``r`` (with a relative
        ``margin`` of 1e−9 so that rounding in the tree cannot drop a pair at ``r``)."""
        p = tree.query_pairs(r * (1 + 1e-9) + 1e-300 if margin else r, output_type="ndarray")
        d = np.sort(pair_distances(z, p[:, 0], p[:, 1])) if len(p) else np.zeros(0)
        self._head = d[:need]

    def __len__(self) -> int:
        return self._len

    def __getitem__(self, i: int) -> float:
        i = int(i)
        if not 0 <= i < self._len:
            raise IndexError(f"index {i} out of range for {self._len} distances")
        if i < len(self._head):
            return float(self._head[i])
        if i < self._fill_end:
            return self._fill_value
        if self._above_cap:
            return np.inf
        raise IndexError(f"distance {i} was not computed (need={self.need})")


def _knn_bound(tree: cKDTree, z: np.ndarray, need: int) -> float:
    """An upper bound of ``D[need − 1]``: the ``need``-th smallest distance among the pairs
    of each plot with its ``q = ⌈2·need/n⌉ + 1`` nearest neighbours (a subset of all
    pairs holding at least ``need`` distinct pairs)."""
    n = len(z)
    q = min(n - 1, -(-2 * need // n) + 1)
    _, j = tree.query(z, k=q + 1)
    i = np.repeat(np.arange(n), q)
    j = j[:, 1:].reshape(-1)
    a, b = np.minimum(i, j), np.maximum(i, j)
    key = _sorted_unique(a[a != b].astype(np.int64) * n + b[a != b])
    if len(key) < need:  # coincident plots: the bounding box's diagonal bounds every pair
        return float(np.hypot(*np.ptp(z, axis=0))) * (1 + 1e-9)
    d = pair_distances(z, key // n, key % n)
    return float(np.partition(d, need - 1)[need - 1]) * (1 + 1e-9)


#: Plots per chunk of the pair search (bounds its temporary arrays).
CHUNK = 4096


def close_pairs(points: np.ndarray, radius: float, own_radius: np.ndarray | None = None,
                keep: Callable[[np.ndarray], np.ndarray] | None = None) -> np.ndarray:
    """Pairs ``i < j`` of ``points`` within ``radius``, as an (m, 2) array, then those
    ``keep(pairs)`` accepts.

    Up to ``max(DENSE_PAIRS, PAIRS_PER_POINT·n)`` pairs within ``radius`` (normal scans):
    ``cKDTree.query_pairs``. Beyond (a burst), :data:`CHUNK` points at a time, each within
    its ``own_radius`` (a point's pairs that ``keep`` can accept must lie within it, e.g. a
    Mahalanobis gate's bound), and ``keep`` is applied chunk by chunk, so memory is
    O(kept pairs); the pairs come sorted by ``i`` then ``j``."""
    from scipy.spatial import cKDTree
    tree = cKDTree(points)
    n = len(points)
    if n < 2 or _pairs_within(tree, radius) <= max(DENSE_PAIRS, PAIRS_PER_POINT * n):
        pairs = tree.query_pairs(radius, output_type="ndarray")
        return pairs[keep(pairs)] if keep is not None and len(pairs) else pairs
    own = np.full(n, radius) if own_radius is None else np.minimum(own_radius, radius)
    by_radius = np.argsort(own, kind="stable")
    parts = []
    for s0 in range(0, n, CHUNK):
        idx = by_radius[s0:s0 + CHUNK]
        near = cKDTree(points[idx]).sparse_distance_matrix(tree, float(own[idx].max()),
                                                           output_type="ndarray")
        i, j = idx[near["i"]].astype(np.int64), near["j"].astype(np.int64)
        p = np.column_stack((i, j))[i < j]
        parts.append(p[keep(p)] if keep is not None and len(p) else p)
    pairs = np.concatenate(parts)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


