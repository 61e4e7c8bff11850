"""The trees a frame did not step, carried into the store after it with their filter
states copied once (issue 30: a frame of one radar's sector steps a few per cent of the
trees; the store's copies were most of a frame's cost).

The former path copied every carried leaf three times: out of the store
(:func:`~mhtrack.mht.timed.split_looked`), into the merged store
(:func:`~mhtrack.mht.numbering.number_and_merge`) and into the pruned one
(:func:`~mhtrack.mht.pruning.prune_after_solve`). Here the carried trees are rows of the
previous store (:class:`Carried`, no copy); :func:`merge_carried` writes the merged
store's columns except the states (:data:`~mhtrack.mht.tree.STATE`: an IMM leaf's
``Pm`` alone is half its bytes), which stay read-only NaN placeholders (as
:func:`~mhtrack.mht.tree.deferred_concat`'s: the solve and N-scan pruning read no
state); :meth:`Merged.take` then copies the states of the rows pruning keeps, once, from
their three sources. The arrays are those of the former path, bit for bit (copies only;
``tests/mht/test_carry.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.mht.numbering import Counter, number_and_merge
from mhtrack.mht.tree import FIELDS, STATE, Leaves, placeholder


@dataclass(frozen=True, slots=True)
class Carried:
    """The leaves of the trees a frame did not step: rows ``rows`` (ascending) of the
    store ``store`` (not copied; the store is never written in place)."""

    store: Leaves
    rows: np.ndarray

    def __len__(self) -> int:
        return int(self.rows.size)

    def leaves(self) -> Leaves:
        """The rows as a store of their own (a copy)."""
        return self.store.take(self.rows)


@dataclass(frozen=True, slots=True)
class Merged:
    """Where the rows of a :func:`merge_carried` store come from: ``at_new`` the rows of
    the grown then the new leaves, ``at_idle`` those of the carried ones."""

    grown: Leaves
    births: Leaves
    carried: Carried
    at_new: np.ndarray
    at_idle: np.ndarray

    def take(self, leaves: Leaves, rows: np.ndarray | None, **columns: np.ndarray) -> Leaves:
        """Rows ``rows`` (ascending; ``None``: all) of ``leaves`` (the merged store) with
        their states copied from their sources and ``columns`` replacing others: the
        arrays of ``replace(merged.take(rows), **columns)`` had the states been merged."""
        at_new, at_idle, src = self.at_new, self.at_idle, self.carried.rows
        if rows is not None:
            keep = np.zeros(len(leaves), bool)
            keep[rows] = True
            index = np.cumsum(keep)
            index -= 1  # each kept row's place among the rows kept
            k_new, k_idle = keep[at_new], keep[at_idle]
            new_rows = k_new.nonzero()[0]
            at_new = index[at_new[new_rows]]
            at_idle, src = index[at_idle[k_idle]], src[k_idle]
        else:
            new_rows = np.arange(at_new.size)
        n_out = len(leaves) if rows is None else rows.size
        g = int(new_rows.searchsorted(len(self.grown)))
        ga, gb = new_rows[:g], new_rows[g:] - len(self.grown)
        source = _source(n_out, at_idle, src)
        cols = {}
        for f in FIELDS:
            if f in columns:
                continue
            if f not in STATE:
                col = getattr(leaves, f)
                cols[f] = col if rows is None else col.take(rows, axis=0)
                continue
            a, b = getattr(self.grown, f), getattr(self.births, f)
            out = _gather(getattr(self.carried.store, f), source, a, b)
            out[at_new[:g]] = a.take(ga, axis=0)
            out[at_new[g:]] = b.take(gb, axis=0)
            cols[f] = out
        return Leaves(**cols, **columns)


def _source(n: int, at_idle: np.ndarray, src: np.ndarray) -> np.ndarray:
    """Per row of a store of ``n`` rows: the carried store's row it reads (``src`` at
    ``at_idle``; 0 elsewhere: a row the grown or new leaves then overwrite)."""
    source = np.zeros(n, np.int64)
    source[at_idle] = src
    return source


def _gather(c: np.ndarray, source: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``c``'s rows ``source``, in the type of the three parts' column (one gather of
    the carried rows, the bulk; the few other rows are written after)."""
    dtype = np.result_type(a, b, c)
    if c.shape[0] == 0:  # nothing carried: every row written after
        return np.empty((source.size, *c.shape[1:]), dtype)
    out = c.take(source, axis=0)
    return out if out.dtype == dtype else out.astype(dtype)


def merge_carried(grown: Leaves, births: Leaves, carried: Carried, nodes: Counter
                  ) -> tuple[Leaves, Merged | None]:
    """:func:`~mhtrack.mht.numbering.number_and_merge` of the grown, new and carried
    leaves with the states deferred (module docstring): ``(store, its sources)``;
    sources ``None`` when the store is whole (grown leaves out of tree order: the
    general path)."""
    n_new = len(grown) + len(births)
    new_tree = np.concatenate((grown.tree, births.tree))
    if np.count_nonzero(new_tree[1:] < new_tree[:-1]):
        return number_and_merge(grown, births, carried.leaves(), nodes), None
    first = nodes.take(n_new)
    store, src = carried.store, carried.rows
    idle_tree = store.tree.take(src)
    # as number_and_merge: each row's place in the stable sort of the concatenation
    at_new = np.arange(n_new) + np.searchsorted(idle_tree, new_tree, side="left")
    at_idle = np.arange(src.size) + np.searchsorted(new_tree, idle_tree, side="right")
    n = n_new + src.size
    source = _source(n, at_idle, src)
    out = {}
    for f in FIELDS:
        a, b, c = getattr(grown, f), getattr(births, f), getattr(store, f)
        if f in STATE:
            out[f] = placeholder((n, *c.shape[1:]))
            continue
        col = _gather(c, source, a, b)
        col[at_new[:len(a)]] = a
        col[at_new[len(a):]] = b
        out[f] = col
    out["node"][at_new] = np.arange(first, first + n_new, dtype=np.int64)
    return Leaves(**out), Merged(grown, births, carried, at_new, at_idle)


def number_frame(grown: Leaves, births: Leaves, idle: Carried | Leaves, nodes: Counter
                 ) -> tuple[Leaves, tuple[Leaves, Leaves] | Merged | None]:
    """The store after a frame, numbered (node ids for the grown then the new leaves),
    and what its deferred states are copied from at pruning: the carried trees merged
    (:func:`merge_carried`); none carried and new trees started, the two parts
    (:func:`~mhtrack.mht.tree.deferred_concat`); else ``None`` (the store is whole)."""
    if isinstance(idle, Carried) and len(idle):
        return merge_carried(grown, births, idle, nodes)
    idle = idle.leaves() if isinstance(idle, Carried) else idle
    parts = (grown, births) if len(idle) == 0 and len(births) else None
    return number_and_merge(grown, births, idle, nodes, parts is not None), parts
