"""No new target on a tracked Mode S reply (mhtrack.mht.births.same_address): hand-built
frames where a confirmed track with address A takes a reply with A (no new tree on it, no
address-less tentative tree takes it) against the same reply with address B, outside the
gate or without an address (a new tree, as before); the rule switched off gives the old
behaviour; without addresses the tracker's output is the same with the rule on or off."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.attributes import PlotAttributes
from mhtrack.mht.attribute_scores import AttributeModel
from mhtrack.mht.births.base import BirthCandidates
from mhtrack.mht.births.same_address import tracked_replies, untracked
from mhtrack.mht.extend import Children
from mhtrack.mht.tracker import MHTTracker
from mhtrack.records import Scan, TrackTable

A, B = 0x3C4591, 0x407A19
OFF = AttributeModel(birth_on_tracked_address=True)


def _scan(k: int, z, address, first_row: int) -> Scan:
    z = np.asarray(z, float).reshape(-1, 2)
    n = len(z)
    attrs = PlotAttributes.from_columns({"address": np.asarray(address, np.int64)}, n)
    return Scan(k, float(k), z, np.zeros(n, np.int64), np.arange(first_row, first_row + n),
                attrs=attrs)


def _frames(address: int, at: tuple[float, float], attributes=None):
    """Frames 0 and 1: replies with address A at (0, 0) and (100, 0), which confirm track
    0, and address-less plots at (300, 0) and (450, 0), which start tentative trees;
    frame 2: one plot (row 4) at ``at`` with ``address``. Returns the tracker after
    frame 2, whether that plot started a tree and the address-less plots' trees."""
    trk = MHTTracker(attributes=attributes)
    trk.step(_scan(0, [[0.0, 0.0], [300.0, 0.0]], [A, -1], 0))
    trk.step(_scan(1, [[100.0, 0.0], [450.0, 0.0]], [A, -1], 2))
    lv = trk.leaves
    assert (lv.ident[lv.chosen & (lv.track == 0), 1] == A).all() and (lv.track == 0).any()
    # the trees started on the address-less plots (rows 1, 3): tentative
    plain = np.unique(lv.tree[np.isin(lv.window, [1, 3]).any(axis=1)
                              & ~np.isin(lv.window, [0, 2]).any(axis=1)])
    assert plain.size == 2 and (lv.track[np.isin(lv.tree, plain)] < 0).all()
    trk.step(_scan(2, [at], [address], 4))
    lv = trk.leaves
    new_tree = bool(((lv.birth == 2) & (lv.window[:, -1] == 4)).any())
    return trk, new_tree, plain


def _takers(trk: MHTTracker, plain: np.ndarray) -> tuple[bool, bool]:
    """Whether leaves take plot row 4: ``(track 0's, those of the trees ``plain`` started
    on the address-less plots)``."""
    lv = trk.leaves
    take = lv.window[:, -1] == 4
    return bool((take & (lv.track == 0)).any()), bool((take & np.isin(lv.tree, plain)).any())


def test_a_reply_a_tree_with_its_address_takes_starts_no_tree():
    trk, new_tree, plain = _frames(A, (200.0, 0.0))
    assert not new_tree
    # track 0 (address A) takes it; the address-less tentative trees do not
    assert _takers(trk, plain) == (True, False)
    assert trk.last_stats.n_births == 0


def test_other_address_outside_the_gate_or_no_address_start_a_tree():
    for address, at in ((B, (200.0, 0.0)), (-1, (200.0, 0.0)), (A, (60_000.0, 0.0))):
        trk, new_tree, plain = _frames(address, at)
        assert new_tree, (address, at)
        assert trk.last_stats.n_births == 1
        # another address or none: the address-less trees take the plot as before
        assert _takers(trk, plain)[1] == (at[0] < 1000), (address, at)


def test_switched_off_the_reply_starts_a_tree_as_before():
    trk, new_tree, plain = _frames(A, (200.0, 0.0), attributes=OFF)
    assert new_tree
    assert _takers(trk, plain) == (True, True)  # the address-less trees take it too


def test_tracked_replies_by_hand():
    # plots 0..3 with addresses A, A, B, none; four children (parent, plot):
    # leaf 0 (A) takes plot 0 → tracked; leaf 1 (no address) takes plot 1 → not;
    # leaf 2 (A) takes plot 2 (B) → not; leaf 0's miss (−1) → nothing
    address = np.array([A, A, B, -1])
    leaf_address = np.array([A, -1, A])
    got = tracked_replies(address, leaf_address, np.array([0, 1, 2, 0]),
                          np.array([0, 1, 2, -1]))
    assert got.tolist() == [True, False, False, False]


def test_untracked_drops_copies_only():
    """Children: the confirmed leaf 0 (A) and the tentative leaves 1 (no address) and
    2 (B) each take plot 0 (A); leaf 3 (no address, confirmed) too. Only leaf 1's child
    goes (tentative, no address); candidates: plot 0's goes, plot 1's (no address) stays.
    Without leaf 0's child (pruned) nothing goes."""
    parent = np.array([0, 1, 1, 2, 3])
    plot = np.array([0, -1, 0, 0, 0])
    children = Children(parent, plot, np.zeros(5), np.zeros(5), np.arange(5))
    leaf_address = np.array([A, -1, B, -1])
    leaf_track = np.array([7, -1, -1, 8])
    cand = BirthCandidates(np.zeros((2, 4)), np.zeros((2, 4, 4)), np.zeros(2), np.zeros(2),
                           np.array([[-1, 10], [-1, 11]]), np.ones(2, np.int64))
    rows, address = np.array([10, 11]), np.array([A, -1])
    kept, births = untracked(children, cand, rows, address, leaf_address, leaf_track)
    assert kept.parent.tolist() == [0, 1, 2, 3] and kept.plot.tolist() == [0, -1, 0, 0]
    assert births.window[:, -1].tolist() == [11]
    pruned = children.take(np.array([1, 2, 3, 4]))
    kept, births = untracked(pruned, cand, rows, address, leaf_address, leaf_track)
    assert len(kept) == 4 and len(births) == 2


def _run(scans: list[Scan], attributes: AttributeModel | None) -> tuple[TrackTable, object]:
    trk = MHTTracker(attributes=attributes)
    out = TrackTable.concat([trk.step(s) for s in scans])
    return out, trk.leaves


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), codes=st.booleans())
def test_without_addresses_the_output_is_the_same_with_the_rule_on_or_off(seed, codes):
    """Random scenes (three targets, uniform clutter) with no attributes, or with codes
    and levels but no address: the rule on and off give the very same rows and leaves."""
    rng = np.random.default_rng(seed)
    scans, row = [], 0
    for k in range(12):
        truth = np.array([[100.0 * k, 0.0], [0.0, 2000.0 + 90.0 * k], [3000.0, 50.0 * k]])
        det = rng.random(3) < 0.9
        z = np.vstack([truth[det] + rng.normal(scale=50.0, size=(int(det.sum()), 2)),
                       rng.uniform(-4000, 4000, (int(rng.integers(0, 6)), 2))])
        n = len(z)
        m = n - int(det.sum())  # clutter: codes and levels at random
        attrs = None if not codes else PlotAttributes.from_columns({
            "mode_3a": np.concatenate((np.array([0o1234, 0o4321, 0o7000])[det],
                                       rng.integers(0, 4096, m))),
            "flight_level": np.concatenate((np.array([300.0, 250.0, 100.0])[det],
                                            rng.uniform(50, 400, m)))}, n)
        scans.append(Scan(k, float(k), z, np.zeros(n, np.int64), np.arange(row, row + n),
                          attrs=attrs))
        row += n
    (a, la), (b, lb) = _run(scans, None), _run(scans, OFF)
    assert len(a) > 0
    for f in ("track_id", "scan", "x", "y", "vx", "vy", "plot", "score"):
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f))
    np.testing.assert_array_equal(la.score, lb.score)
    np.testing.assert_array_equal(la.window, lb.window)
