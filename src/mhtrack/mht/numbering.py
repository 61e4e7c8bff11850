"""Ids that are consecutive and never reused: trees, track ids and leaf nodes."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mhtrack.mht.tree import FIELDS, Leaves, deferred_concat


class Counter:
    """The next free id of one kind; :meth:`take` reserves ``n`` consecutive ids."""

    def __init__(self, start: int = 0) -> None:
        self.next = int(start)

    def take(self, n: int) -> int:
        """Reserve ids ``first … first + n − 1`` and return ``first``."""
        first = self.next
        self.next += int(n)
        return first


def number_nodes(leaves: Leaves, nodes: Counter) -> Leaves:
    """Give every leaf of the scan a new node id, ascending in row order (the links of
    :mod:`mhtrack.mht.history`)."""
    first = nodes.take(len(leaves))
    return replace(leaves, node=np.arange(first, first + len(leaves), dtype=np.int64))


def number_and_merge(grown: Leaves, births: Leaves, idle: Leaves, nodes: Counter,
                     defer_states: bool = False) -> Leaves:
    """The store after a scan, built with one copy: the grown and the new trees' leaves
    get node ids (:func:`number_nodes`, in that order), then the leaves of the trees the
    frame did not step join them in tree order (stable) — the same arrays as numbering
    ``Leaves.concat(grown, births)``, concatenating ``idle`` and sorting by tree (stable),
    without the intermediate copies (``tests/mht/test_numbering.py``). ``defer_states``
    (no ``idle`` leaves): the states are not copied yet
    (:func:`~mhtrack.mht.tree.deferred_concat`)."""
    if len(idle) == 0:
        if not defer_states:
            return number_nodes(Leaves.concat(grown, births), nodes)
        first = nodes.take(len(grown) + len(births))
        return deferred_concat(grown, births, node=np.arange(first, nodes.next, dtype=np.int64))
    n_new = len(grown) + len(births)
    first = nodes.take(n_new)
    new_tree = np.concatenate((grown.tree, births.tree))
    if np.count_nonzero(new_tree[1:] < new_tree[:-1]):  # not sorted: sort all (stable)
        cols = {f: np.concatenate((getattr(grown, f), getattr(births, f), getattr(idle, f)))
                for f in FIELDS}
        cols["node"] = np.concatenate((np.arange(first, first + n_new, dtype=np.int64),
                                       idle.node))
        order = cols["tree"].argsort(kind="stable")
        return Leaves(**{k: np.take(v, order, axis=0) for k, v in cols.items()})
    # both parts sorted by tree: each row's place in the stable sort of their
    # concatenation is its rank in its part plus the rows of the other part before it
    # (the new rows first among equal trees); one write of every column
    at_new = np.arange(n_new) + np.searchsorted(idle.tree, new_tree, side="left")
    at_idle = np.arange(len(idle)) + np.searchsorted(new_tree, idle.tree, side="right")
    out = {}
    for f in FIELDS:
        a, b, c = getattr(grown, f), getattr(births, f), getattr(idle, f)
        col = np.empty((n_new + len(idle), *c.shape[1:]), np.result_type(a, b, c))
        col[at_new[:len(a)]] = a
        col[at_new[len(a):]] = b
        col[at_idle] = c
        out[f] = col
    out["node"][at_new] = np.arange(first, first + n_new, dtype=np.int64)
    return Leaves(**out)
