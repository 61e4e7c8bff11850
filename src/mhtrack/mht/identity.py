"""Track identity: which tree carries which track id, from scan to scan.

A track id is given once, when a tree is confirmed (:func:`confirm`), in tree-id order,
and never reused. The best global hypothesis may, at a later scan, prefer a *new*
tentative tree for a target over the tree that carried its track — the new tree took a
different branch through the same plots. The track then follows its plots, not its tree
(:func:`hand_over`): the new tree takes over the id of the track it shares plots with, so
the output does not end one track and start another on the same target.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mhtrack.mht.numbering import Counter
from mhtrack.mht.tree import Leaves, contains


@dataclass(frozen=True, slots=True)
class Reported:
    """Track ids reported at the previous scan and their plots at scans ``k−N … k−1``
    (window shifted to the current scan's columns ``0 … N−1``)."""

    track: np.ndarray
    window: np.ndarray

    @classmethod
    def of(cls, leaves: Leaves, *, by_id: bool = False,
           reported: np.ndarray | None = None) -> Reported:
        """What the leaves of the last scan reported (chosen, confirmed; ``reported``:
        that mask, when known); ``by_id``: the whole windows (a tree's columns are its
        own looks, not the scans)."""
        rep = leaves.reported() if reported is None else reported
        rows = rep.nonzero()[0]
        window = leaves.window.take(rows, axis=0)
        return cls(leaves.track.take(rows), window if by_id else window[:, 1:])


def hand_over(leaves: Leaves, previous: Reported, *, by_id: bool = False) -> Leaves:
    """A tentative tree whose chosen leaf shares a plot (within the window) with a track
    reported at the previous scan that the best hypothesis no longer carries takes over
    that track's id; the old tree gives it up. Most shared plots first, then lower tree,
    then lower track id; each tree and each id at most once. A plot is shared at the same
    scan column, or (``by_id``: frames of several sensors) by its id in any column."""
    track = leaves.track
    if previous.track.size == 0:
        return leaves
    chosen = leaves.chosen.nonzero()[0]
    carried = track[chosen]
    cand = chosen[carried < 0]
    if cand.size == 0:
        return leaves
    lost = ~contains(carried[carried >= 0], previous.track)
    if np.count_nonzero(lost) == 0:
        return leaves
    track = track.copy()
    lost_ids, lost_win = previous.track[lost], previous.window[lost]
    if by_id:
        win = leaves.window[cand]
        shared = ((win[:, None, :, None] == lost_win[None, :, None, :])
                  & (win[:, None, :, None] >= 0)).sum((2, 3))
    else:
        win = leaves.window[cand, :-1]
        shared = ((win[:, None, :] == lost_win[None, :, :]) & (win[:, None, :] >= 0)).sum(2)
    ci, li = np.nonzero(shared)
    order = np.lexsort((lost_ids[li], leaves.tree[cand[ci]], -shared[ci, li]))
    taken_c, taken_l = np.zeros(cand.size, bool), np.zeros(lost_ids.size, bool)
    for c, k in zip(ci[order].tolist(), li[order].tolist(), strict=True):
        if taken_c[c] or taken_l[k]:
            continue
        taken_c[c] = taken_l[k] = True
        tid = lost_ids[k]
        track[track == tid] = -1  # the old tree gives the id up
        track[leaves.tree == leaves.tree[cand[c]]] = tid
    return replace(leaves, track=track)


def confirm(leaves: Leaves, confirms: np.ndarray, tracks: Counter) -> Leaves:
    """Every tentative tree whose chosen leaf ``confirms`` (a mask over leaves, the SPRT's
    rule) gets the next track id, in tree-id order; all its leaves carry it."""
    new = leaves.chosen & (leaves.track < 0) & confirms
    if np.count_nonzero(new) == 0:
        return leaves
    track = leaves.track.copy()
    trees = leaves.tree[new]  # one chosen leaf per tree, ascending
    first = tracks.take(trees.size)
    ids = np.arange(first, first + trees.size, dtype=np.int64)
    j = np.minimum(trees.searchsorted(leaves.tree), trees.size - 1)
    hit = trees[j] == leaves.tree
    track[hit] = ids[j[hit]]
    return replace(leaves, track=track)


def newly_confirmed(leaves: Leaves, first_new: int) -> np.ndarray:
    """Rows of the chosen leaves whose track id is ``first_new`` or later (given at this
    scan)."""
    return (leaves.chosen & (leaves.track >= first_new)).nonzero()[0]
