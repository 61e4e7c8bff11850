"""No new target on a tracked Mode S reply (mhtrack.mht.births.same_address): hand-built
frames where a confirmed track with address A on three plots takes a reply with A (no
new tree on it, no address-less tentative tree takes it) against the same reply with
address B, outside the gate, without an address, or after a track on two plots only (a
new tree, as before); the witnesses and the masks by hand; the rule switched off gives the old
behaviour; without addresses the tracker's output is the same with the rule on or off."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.attributes import PlotAttributes
from mhtrack.mht.attribute_scores import AttributeModel
from mhtrack.mht.births.base import BirthCandidates
from mhtrack.mht.births.same_address import tracked_replies, untracked, witnesses
from mhtrack.mht.extend import Children
from mhtrack.mht.tracker import MHTTracker
from mhtrack.mht.tree import Leaves
from mhtrack.records import Scan, TrackTable

A, B = 0x3C4591, 0x407A19
OFF = AttributeModel(birth_on_tracked_address=True)


def _scan(k: int, z, address, first_row: int) -> Scan:
    z = np.asarray(z, float).reshape(-1, 2)
    n = len(z)
    attrs = PlotAttributes.from_columns({"address": np.asarray(address, np.int64)}, n)
    return Scan(k, float(k), z, np.zeros(n, np.int64), np.arange(first_row, first_row + n),
                attrs=attrs)


REPLIES, PLAIN = (0, 2, 4), (1, 3, 5)  # plot rows of frames 0–2
SCATTERED = ([300.0, 600.0], [900.0, -500.0], [-200.0, -400.0])  # no track among them


def _frames(address: int, at: tuple[float, float], attributes=None):
    """Frames 0–2: replies with address A at (0, 0), (100, 0), (200, 0) (rows 0, 2, 4),
    which confirm track 0, and address-less plots scattered near them (rows 1, 3, 5),
    which start tentative trees; frame 3: one plot (row 6) at ``at`` with
    ``address``. Returns the tracker after frame 3, whether that plot started a tree and
    the trees started on the address-less plots."""
    trk, plain = MHTTracker(attributes=attributes), []
    for k in range(3):
        trk.step(_scan(k, [[100.0 * k, 0.0], SCATTERED[k]], [A, -1], 2 * k))
        lv = trk.leaves
        plain += lv.tree[(lv.birth == k) & (lv.window[:, -1] == PLAIN[k])].tolist()
    lv = trk.leaves
    # track 0 carries A on three plots: a witness (same_address.witnesses)
    assert ((lv.track == 0) & lv.chosen & (lv.ident[:, 1] == A) & (lv.n_updates == 3)).any()
    assert len(plain) == 3 and (lv.track[np.isin(lv.tree, plain)] < 0).all()
    trk.step(_scan(3, [at], [address], 6))
    lv = trk.leaves
    new_tree = bool(((lv.birth == 3) & (lv.window[:, -1] == 6)).any())
    return trk, new_tree, np.asarray(plain)


def _takers(trk: MHTTracker, plain: np.ndarray) -> tuple[bool, bool]:
    """Whether leaves take plot row 6: ``(track 0's, an address-less leaf's of the trees
    ``plain`` started on the address-less plots)`` — address-less before row 6: no reply
    row in its window."""
    lv = trk.leaves
    take = lv.window[:, -1] == 6
    addressless = ~np.isin(lv.window[:, :-1], REPLIES).any(axis=1)
    return bool((take & (lv.track == 0)).any()), \
        bool((take & np.isin(lv.tree, plain) & addressless).any())


def test_a_reply_a_tree_with_its_address_takes_starts_no_tree():
    trk, new_tree, plain = _frames(A, (300.0, 0.0))
    assert not new_tree
    # track 0 (address A) takes it; the address-less tentative trees do not
    assert _takers(trk, plain) == (True, False)
    assert trk.last_stats.n_births == 0


def test_other_address_outside_the_gate_or_no_address_start_a_tree():
    for address, at in ((B, (300.0, 0.0)), (-1, (300.0, 0.0)), (A, (60_000.0, 0.0))):
        trk, new_tree, plain = _frames(address, at)
        assert new_tree, (address, at)
        assert trk.last_stats.n_births == 1
        # another address or none: the address-less trees take the plot as before
        assert _takers(trk, plain)[1] == (at[0] < 1000), (address, at)


def test_switched_off_the_reply_starts_a_tree_as_before():
    trk, new_tree, plain = _frames(A, (300.0, 0.0), attributes=OFF)
    assert new_tree
    assert _takers(trk, plain) == (True, True)  # the address-less trees take it too


def test_a_young_track_is_no_witness():
    """After two frames track 0 rests on two plots: the reply starts its tree as before
    (a restart with an unknown velocity; same_address, *Witness*)."""
    trk = MHTTracker()
    for k in range(2):
        trk.step(_scan(k, [[100.0 * k, 0.0]], [A], k))
    lv = trk.leaves
    assert ((lv.track == 0) & lv.chosen & (lv.n_updates == 2)).any()
    trk.step(_scan(2, [[200.0, 0.0]], [A], 2))
    assert trk.last_stats.n_births == 1


def _leaves(track, address, n_updates) -> Leaves:
    n = len(track)
    lv = Leaves(np.zeros((n, 4)), np.tile(np.eye(4), (n, 1, 1)), np.ones(n), np.ones(n),
                np.arange(n), np.asarray(track), np.zeros(n, np.int64),
                np.asarray(n_updates), np.full((n, 4), -1), np.ones(n, bool),
                np.zeros((n, 0)), np.zeros((n, 0, 4)), np.zeros((n, 0, 4, 4)),
                np.arange(n), np.full(n, -1), np.zeros(n))
    return dataclasses.replace(lv, ident=np.column_stack((np.full(n, -1),
                                                          np.asarray(address))))


def test_witnesses_and_tracked_replies_by_hand():
    # leaves: confirmed A on 3 plots (witness), confirmed A on 2, tentative A on 5,
    # confirmed without address on 9
    lv = _leaves([7, 8, -1, 9], [A, A, A, -1], [3, 2, 5, 9])
    assert witnesses(lv).tolist() == [True, False, False, False]
    # plots 0..3 with addresses A, A, B, none; children (parent, plot): witness 0 takes
    # plot 0 → tracked; leaves 1, 2 (A, no witnesses) take plot 1 → not; witness 0
    # takes plot 2 (B) → not; witness 0's miss → nothing
    address = np.array([A, A, B, -1])
    got = tracked_replies(address, lv.ident[:, 1], np.array([0, 1, 2, 0, 0]),
                          np.array([0, 1, 1, 2, -1]), witnesses(lv))
    assert got.tolist() == [True, False, False, False]


def test_untracked_drops_copies_only():
    """Children of plot 0 (A): the witness 0 (A), the tentative leaves 1 (no address) and
    2 (B), the confirmed leaf 3 (no address). Only leaf 1's goes (tentative, no address);
    candidates: plot 0's goes, plot 1's (no address) stays. Without the witness's child
    (pruned) nothing goes."""
    lv = _leaves([7, -1, -1, 8], [A, -1, B, -1], [4, 1, 1, 4])
    parent = np.array([0, 1, 1, 2, 3])
    plot = np.array([0, -1, 0, 0, 0])
    children = Children(parent, plot, np.zeros(5), np.zeros(5), np.arange(5))
    cand = BirthCandidates(np.zeros((2, 4)), np.zeros((2, 4, 4)), np.zeros(2), np.zeros(2),
                           np.array([[-1, 10], [-1, 11]]), np.ones(2, np.int64))
    rows, address = np.array([10, 11]), np.array([A, -1])
    kept, births = untracked(children, cand, rows, address, lv)
    assert kept.parent.tolist() == [0, 1, 2, 3] and kept.plot.tolist() == [0, -1, 0, 0]
    assert births.window[:, -1].tolist() == [11]
    pruned = children.take(np.array([1, 2, 3, 4]))
    kept, births = untracked(pruned, cand, rows, address, lv)
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
