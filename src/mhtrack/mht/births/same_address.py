"""No new target on a Mode S reply that a tree with the same address already takes.

**Rule.** Call a plot with Mode S address ``A`` *tracked* when a *witness* — a leaf of a
confirmed track whose address is ``A`` (:attr:`~mhtrack.mht.tree.Leaves.ident`: the
first address its plots gave) and whose branch holds at least :data:`MIN_PLOTS` plots —
has a child that takes the plot and survived this frame's pruning
(:func:`~mhtrack.mht.pruning.prune_children`). Then

1. a tracked plot starts no new tree (the birth process's candidate on it is dropped);
2. a leaf of a *tentative* tree that has no address yet does not take a tracked plot
   (that child is dropped before its Kalman update; the leaf's other children stay).

Every other plot and child is as before: a plot without an address, with another
address, outside every witness's gate, or whose only witness child was pruned starts its
tree; confirmed tracks and leaves with an address keep all their children
(``docs/mht.md``, *No new target on a tracked address*).

**Why.** In the track-oriented MHT (P1 Fig. 1; Reid 1979's "new target") a plot starts a
tree, and a tentative tree takes plots, so that the hypotheses cover "a target no tree
follows yet". An ICAO 24-bit address belongs to one airframe (ICAO Annex 10 vol. III,
the aircraft addressing system; Mode S replies carry it under a 24-bit parity), so a new
target with address ``A`` while a track with ``A`` has a branch on the plot is that
aircraft again. A new tree on the plot (1) copies the branch; a tentative tree without
an address (started on a clutter plot, or on the aircraft's own primary-only plot) that
takes the reply (2) becomes a copy with a made-up start. Both gain the reply's ~20 nats
(:mod:`mhtrack.mht.attribute_scores`) at each of the aircraft's next replies, are held
back from confirmation by the one-track-per-address rule (:mod:`mhtrack.mht.resume`) and
sit in the aircraft's cluster until N-scan pruning removes them: on issue 30's dense scene
~5 per aircraft, most of them of kind 2 (``docs/performance.md``, *With secondary-radar
attributes*). The hypotheses they stand for are the branch's already; only the copies go.
Attribute (IFF/SSR) data in association and initiation: Blackman & Popoli (1999),
*Design and Analysis of Modern Tracking Systems*, ch. 11; this form of the rule is ours.

**Witness.** A new tree on a reply is not only a copy: it restarts from the plot with
the one-point state (velocity unknown, :func:`~mhtrack.mht.tree.one_point_state`). A
branch whose velocity rests on two plots is wrong when the aircraft turned or slowed
between them, and then the restart is what follows it: with any leaf with the address as
witness, a landing aircraft of ``opensky-radars`` seed 2 lost its track and took a second
id (fragmentations 13 → 15, identity switches 1 → 2), seed 3 likewise (14 → 15). A
confirmed track's branch with three plots or more keeps those seeds' figures exactly and
removes the copies as well (``docs/performance.md``).

**Garbled addresses.** Only an exact match with a witness that takes the plot acts: a
garbled address (another value) is scored and starts its tree as before, and a real new
aircraft loses its tree (or a tentative tree its reply) only if its address was decoded
as exactly that of a tracked aircraft whose gate the plot lies in (about ``ε_S`` times
the chance of that one value among 2²⁴); its next reply starts its tree then. A Mode A/C
aircraft (no address) keeps every plot without an address. Without addresses nothing
changes: the tracker calls this only for frames with attributes
(``AttributeModel.birth_on_tracked_address`` = True switches it off).
"""

from __future__ import annotations

import numpy as np

from mhtrack.mht.attribute_scores import positions
from mhtrack.mht.births.base import BirthCandidates
from mhtrack.mht.extend import Children
from mhtrack.mht.tree import Leaves

#: Plots (the root included) a confirmed track's branch must rest on to stand for its
#: aircraft: its velocity then comes from three plots or more, not from two that a turn
#: between them makes wrong (module docstring, *Witness*).
MIN_PLOTS = 3


def witnesses(leaves: Leaves) -> np.ndarray:
    """Mask over ``leaves``: a confirmed track's leaf (``track >= 0``) with an address and
    at least :data:`MIN_PLOTS` plots (module docstring)."""
    return (leaves.track >= 0) & (leaves.n_updates >= MIN_PLOTS) & (leaves.ident[:, 1] >= 0)


def tracked_replies(address: np.ndarray, leaf_address: np.ndarray, parent: np.ndarray,
                    plot: np.ndarray, witness: np.ndarray) -> np.ndarray:
    """Mask over a frame's plots (``address`` (n,), ``-1`` none): a child (``parent``
    leaf, ``plot`` index, ``-1`` a miss) of a ``witness`` (mask over leaves) takes the
    plot, and its parent's address ``leaf_address[parent]`` equals the plot's."""
    out = np.zeros(address.size, bool)
    took = (plot >= 0) & witness[parent]
    j = plot[took]
    a = leaf_address[parent[took]]
    out[j[(a >= 0) & (a == address[j])]] = True
    return out


def untracked_births(cand: BirthCandidates, rows: np.ndarray,
                     tracked: np.ndarray) -> BirthCandidates:
    """The candidates whose plot of this frame (their window's last column, found in the
    frame's plot ``rows``) is not ``tracked`` (mask over the plots,
    :func:`tracked_replies`); candidates whose last plot is not of this frame are kept."""
    if len(cand) == 0 or rows.size == 0 or not tracked.any():
        return cand
    j = positions(rows, cand.window[:, -1])
    drop = (j >= 0) & tracked[np.maximum(j, 0)]
    return cand if not drop.any() else cand.take(np.flatnonzero(~drop))


def untracked(children: Children, cand: BirthCandidates, rows: np.ndarray,
              address: np.ndarray, leaves: Leaves) -> tuple[Children, BirthCandidates]:
    """Both parts of the rule (module docstring) on the children that survived pruning
    (their parents ``leaves``) and on the birth candidates: ``(children, candidates)``
    without those that copy a tracked reply."""
    ident = leaves.ident[:, 1]
    tracked = tracked_replies(address, ident, children.parent, children.plot,
                              witnesses(leaves))
    if not tracked.any():
        return children, cand
    j, parent = children.plot, children.parent
    copy = (j >= 0) & tracked[np.maximum(j, 0)] & (ident[parent] < 0) & \
        (leaves.track[parent] < 0)
    if copy.any():
        children = children.take(np.flatnonzero(~copy))
    return children, untracked_births(cand, rows, tracked)
