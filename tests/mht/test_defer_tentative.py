"""``MHTConfig.defer_tentative``: N-scan pruning does not commit tentative trees (rule 1
of :func:`~mhtrack.mht.pruning.n_scan_keep` waits; rule 2 still holds) — by hand on
``test_pruning``'s example, against a loop written from the rules' statement, and in the
tracker."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.mht.crossing_fixture import simulate
from tests.mht.test_pruning import TREE, WINDOW

from mhtrack.clutter import KnownClutter
from mhtrack.mht import MHTConfig, MHTTracker, n_scan_keep
from mhtrack.mht.tree import segment_starts


def test_deferred_tree_keeps_what_only_rule_1_would_cut():
    chosen = np.array([0, 5])
    assert np.flatnonzero(n_scan_keep(TREE, WINDOW[:, 0], chosen)).tolist() == [0, 1, 5, 8]
    # tree 10 tentative: its miss at k−2 (leaf 3) stays; leaves 2 and 4 hold plot 8,
    # which tree 20's chosen leaf uses at k−2 (rule 2): still pruned
    defer = TREE == 10
    assert np.flatnonzero(n_scan_keep(TREE, WINDOW[:, 0], chosen, defer=defer)
                          ).tolist() == [0, 1, 3, 5, 8]
    # tree 20 tentative: its miss at k−2 (leaf 6) stays
    defer = TREE == 20
    assert np.flatnonzero(n_scan_keep(TREE, WINDOW[:, 0], chosen, defer=defer)
                          ).tolist() == [0, 1, 5, 6, 8]


def _by_the_rules(tree, oldest, chosen, defer):
    """Rule 1 (not for deferred leaves) and rule 2, leaf by leaf."""
    keep = []
    for i in range(tree.size):
        drop = False
        for c in chosen:
            if tree[c] == tree[i] and oldest[i] != oldest[c] and not defer[i]:
                drop = True  # rule 1
            if tree[c] != tree[i] and oldest[c] != -1 and oldest[c] == oldest[i]:
                drop = True  # rule 2
        keep.append(not drop)
    return np.array(keep, bool)


@st.composite
def _store(draw):
    n = draw(st.integers(1, 30))
    tree = np.sort(np.array(draw(st.lists(st.integers(0, 6), min_size=n, max_size=n))))
    oldest = np.array(draw(st.lists(st.integers(-1, 5), min_size=n, max_size=n)))
    # at most one chosen leaf per tree, ascending
    starts = segment_starts(tree)
    ends = np.append(starts[1:], n)
    pick = draw(st.lists(st.booleans(), min_size=starts.size, max_size=starts.size))
    chosen = np.array([draw(st.integers(s, e - 1)) for s, e, p in
                       zip(starts, ends, pick, strict=True) if p], np.int64)
    # distinct plots among the chosen leaves (a hypothesis never uses one plot twice)
    if chosen.size:
        used = oldest[chosen]
        dup = np.zeros(chosen.size, bool)
        seen: set[int] = set()
        for j, p in enumerate(used.tolist()):
            dup[j] = p != -1 and p in seen
            seen.add(p)
        chosen = chosen[~dup]
    tentative = draw(st.lists(st.booleans(), min_size=7, max_size=7))
    defer = np.array(tentative)[tree]  # per tree, as the tracker's track < 0
    return tree, oldest, chosen, defer


@settings(max_examples=300, deadline=None)
@given(_store())
def test_against_the_rules_written_as_a_loop(store):
    tree, oldest, chosen, defer = store
    got = n_scan_keep(tree, oldest, chosen, defer=defer)
    np.testing.assert_array_equal(got, _by_the_rules(tree, oldest, chosen, defer))
    np.testing.assert_array_equal(n_scan_keep(tree, oldest, chosen),
                                  n_scan_keep(tree, oldest, chosen,
                                              defer=np.zeros(tree.size, bool)))


def _committed(leaves):
    """Per tree with a chosen leaf: whether all its leaves hold the chosen one's plot at
    ``k − N`` (what rule 1 leaves)."""
    out = {}
    for i in np.flatnonzero(leaves.chosen):
        same = leaves.tree == leaves.tree[i]
        out[int(leaves.tree[i])] = (bool(leaves.track[i] >= 0),
                                    bool((leaves.window[same, 0] == leaves.window[i, 0]).all()))
    return out


def test_tracker_defers_tentative_trees_only():
    sim = simulate(n_scans=12, clutter_rate=40.0, seed=3)
    runs = {}
    for defer in (False, True):
        trk = MHTTracker(MHTConfig(defer_tentative=defer), KnownClutter(sim.clutter_density))
        seen = []
        for scan in sim.scans:
            before = trk.leaves  # the tracks as they were when the frame was pruned
            trk.step(scan)
            seen.append((before, _committed(trk.leaves)))
        runs[defer] = seen
    # P1's rule: every tree of the best hypothesis is committed after each frame
    assert all(ok for _, c in runs[False] for _, ok in c.values())
    # deferred: the trees confirmed before the frame are still committed, and some
    # tentative tree of the best hypothesis kept a branch rule 1 would have cut
    uncommitted = 0
    for before, c in runs[True]:
        old = set(before.tree[before.track >= 0].tolist())
        for t, (_, ok) in c.items():
            assert ok or t not in old
            uncommitted += not ok
    assert uncommitted > 0
