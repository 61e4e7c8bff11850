"""Secondary-radar attributes in the MHT score (mhtrack.mht.attribute_scores): hand-worked
likelihood ratios, the vertical filter against the matrix form, a constructed crossing at
2 000 ft that swaps without attributes and never with, and plots without attributes scored
exactly as before."""

import math

import numpy as np
import pytest

from mhtrack.attributes import PlotAttributes
from mhtrack.mht.attribute_scores import (
    AttributeModel,
    grow_attributes,
    pair_increments,
    predict_level,
)
from mhtrack.mht.tracker import MHTTracker
from mhtrack.records import Scan, TrackTable

M = AttributeModel()


def _one_pair(level=None, ident=(-1, -1), **cols):
    lv = np.full((1, 7), np.nan) if level is None else np.asarray([level], float)
    attrs = PlotAttributes.from_columns({k: np.asarray([v]) for k, v in cols.items()}, 1)
    return float(pair_increments(M, lv, np.asarray([ident], np.int64), attrs,
                                 np.array([10.0]), np.array([0]), np.array([0]))[0])


def test_code_match_mismatch_and_garbled_by_hand():
    # ε_A = 0.02, ε_A,g = 0.3, q_A = 0.02 (the defaults): λ = (1 − ε)/q or ε/(1 − q)
    code = 0o1234
    assert _one_pair(ident=(code, -1), mode_3a=code) == pytest.approx(math.log(0.98 / 0.02))
    assert _one_pair(ident=(code, -1), mode_3a=0o1235) == pytest.approx(
        math.log(0.02 / 0.98))
    garbled = _one_pair(ident=(code, -1), mode_3a=0o1235, mode_3a_g=1)
    assert garbled == pytest.approx(math.log(0.3 / 0.98))  # −1.18: a cost ...
    assert math.isfinite(garbled) and garbled > math.log(0.02 / 0.98)  # ... not a veto
    assert _one_pair(ident=(code, -1), mode_3a=0o1235, mode_3a_v=1) == pytest.approx(
        math.log(0.3 / 0.98))
    assert _one_pair(ident=(-1, -1), mode_3a=code) == 0.0  # the track has no code yet
    assert _one_pair(ident=(code, -1)) == 0.0  # the plot has none


def test_mode_s_address_mismatch_strongly_penalised():
    a = 0x3C4591
    match = _one_pair(ident=(-1, a), address=a)
    other = _one_pair(ident=(-1, a), address=0x407A19)
    assert match == pytest.approx(math.log(0.999 / 0.01))
    assert other == pytest.approx(math.log(0.001 / 0.99))  # −6.9
    # the swing between the two explanations: a factor of ~10⁵ against the wrong address
    assert match - other == pytest.approx(math.log(0.999 * 0.99 / (0.001 * 0.01)))
    assert match - other > math.log(9e4)


def test_flight_level_ratio_by_hand():
    # a level state at FL 300 (variance 1, rate 0 with variance 0.01) at t = 0, plot at t = 10
    level = [300.0, 0.0, 1.0, 0.0, 0.01, 0.0, 0.0]
    # P⁻_hh = 1 + 100·0.01 + q·1000/3 = 2 + 10/3; S = P⁻_hh + σ² = 5.5833...
    S = 1 + 100 * 0.01 + M.q_level * 1000 / 3 + M.sigma_level ** 2
    for h in (300.0, 302.0, 320.0):
        dens = math.exp(-0.5 * (h - 300) ** 2 / S) / math.sqrt(2 * math.pi * S)
        want = math.log(0.99 * dens * 500 + 0.01)
        assert _one_pair(level=level, flight_level=h) == pytest.approx(want, rel=1e-12)
    # 2 000 ft off costs at most ln ε_C (the outlier floor), never more
    assert _one_pair(level=level, flight_level=320.0) == pytest.approx(math.log(0.01), abs=1e-6)
    garbled = _one_pair(level=level, flight_level=320.0, flight_level_g=1)
    assert garbled == pytest.approx(math.log(0.2), abs=1e-6)


def test_level_prediction_is_the_matrix_form():
    rng = np.random.default_rng(3)
    for _ in range(20):
        A = rng.normal(size=(2, 2))
        P = A @ A.T + np.eye(2) * 0.1
        h, r, t0, t = rng.normal(300, 50), rng.normal(0, 0.5), rng.uniform(0, 5), \
            rng.uniform(0, 30)
        dt = t - t0
        F = np.array([[1, dt], [0, 1]])
        Q = M.q_level * np.array([[abs(dt) ** 3 / 3, dt * abs(dt) / 2],
                                  [dt * abs(dt) / 2, abs(dt)]])
        Pp = F @ P @ F.T + Q
        got = predict_level(np.array([[h, r, P[0, 0], P[0, 1], P[1, 1], t0]]),
                            np.array([t]), M.q_level)
        np.testing.assert_allclose([g[0] for g in got], [h + r * dt, Pp[0, 0], Pp[0, 1],
                                                         Pp[1, 1]], rtol=1e-12)


def test_vertical_filter_learns_a_climb():
    # validated levels of a steady 2 000 ft/min climb (1/3 FL/s), every 4 s
    level, ident = np.full((1, 7), np.nan), np.full((1, 2), -1, np.int64)
    for k in range(40):
        t = 4.0 * k
        attrs = PlotAttributes.from_columns({"flight_level": np.array([100 + t / 3])}, 1)
        level, ident = grow_attributes(M, level, ident, attrs, np.array([t]), np.array([0]))
    assert level[0, 1] == pytest.approx(1 / 3, abs=0.02)
    assert level[0, 0] == pytest.approx(100 + 156 / 3, abs=0.5)
    # a garbled level does not move the state; a new validated code and address are kept
    attrs = PlotAttributes.from_columns({"flight_level": np.array([50.0]),
                                         "flight_level_g": np.array([1]),
                                         "mode_3a": np.array([0o7000]),
                                         "address": np.array([0xABCDEF])}, 1)
    after, ident = grow_attributes(M, level, ident, attrs, np.array([160.0]), np.array([0]))
    np.testing.assert_array_equal(after, level)
    assert ident.tolist() == [[0o7000, 0xABCDEF]]


def _crossing(seed, attrs_on, *, levels=(300.0, 320.0), addresses=None, n=60):
    """Two aircraft on crossing tracks 3° apart, at the same place at scan 30 (equal
    positions), FL 300 and 320 (2 000 ft); P_D 0.9, σ 100 m, no clutter. Returns the
    number of tracks whose plots came from both aircraft, and the track ids."""
    rng = np.random.default_rng(seed)
    trk = MHTTracker()
    origin, rows, outs = [], 0, []
    for k in range(n):
        xs = -3000 + 100.0 * k
        z, o = [], []
        for i, y in enumerate((0.03 * xs, -0.03 * xs)):
            if rng.random() < 0.9:
                z.append(np.array([xs, y]) + rng.normal(scale=100.0, size=2))
                o.append(i)
        perm = rng.permutation(len(z))
        z, o = np.asarray(z).reshape(-1, 2)[perm], np.asarray(o, np.int64)[perm]
        attrs = None
        if attrs_on:
            cols = {"flight_level": np.asarray(levels)[o], "plot_type": np.full(len(o), 2)}
            if addresses is not None:
                cols["address"] = np.asarray(addresses)[o]
            attrs = PlotAttributes.from_columns(cols, len(o))
        outs.append(trk.step(Scan(k, float(k), z, np.zeros(len(o), np.int64),
                                  np.arange(rows, rows + len(o)), attrs=attrs)))
        origin += o.tolist()
        rows += len(o)
    tt = TrackTable.concat(outs)
    used = tt.plot >= 0
    src = np.asarray(origin)[tt.plot[used]]
    mixed = sum(len(set(src[tt.track_id[used] == t].tolist())) > 1
                for t in np.unique(tt.track_id))
    return mixed, np.unique(tt.track_id).size


SEEDS = range(1, 9)


def test_crossing_at_2000_ft_never_swaps_with_flight_levels():
    with_levels = [_crossing(s, True) for s in SEEDS]
    assert all(mixed == 0 for mixed, _ in with_levels), with_levels
    assert all(n == 2 for _, n in with_levels), with_levels  # one id per aircraft


def test_the_same_crossing_swaps_without_attributes():
    without = [_crossing(s, False) for s in SEEDS]
    assert sum(mixed > 0 for mixed, _ in without) >= len(SEEDS) // 2, without


def test_same_level_different_addresses_never_swaps():
    runs = [_crossing(s, True, levels=(300.0, 300.0), addresses=(0x3C4591, 0x407A19))
            for s in SEEDS]
    assert all(mixed == 0 for mixed, _ in runs), runs


def test_plots_without_attributes_score_as_before():
    """Absent attributes (every column empty) give the very floats of ``attrs=None``."""
    rng = np.random.default_rng(7)
    outs = {}
    for mode in ("none", "absent"):
        trk, res = MHTTracker(), []
        r = np.random.default_rng(11)
        for k in range(25):
            z = np.vstack([[100.0 * k, 0.0], [0.0, 80.0 * k], r.uniform(-3000, 3000, (3, 2))])
            z = z + r.normal(scale=50.0, size=z.shape)
            a = None if mode == "none" else PlotAttributes.absent(len(z))
            res.append(trk.step(Scan(k, float(k), z, np.zeros(len(z), np.int64),
                                     np.arange(5 * k, 5 * k + 5), attrs=a)))
        outs[mode] = (TrackTable.concat(res), trk.leaves)
    (a, la), (b, lb) = outs["none"], outs["absent"]
    assert len(a) > 0 and rng is not None
    for f in ("track_id", "x", "y", "vx", "vy", "plot", "score"):
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f))
    np.testing.assert_array_equal(la.score, lb.score)


def test_save_restore_with_attributes_continues_bit_for_bit(tmp_path):
    """Vertical states, codes, addresses and the address book are saved with the state."""
    rng = np.random.default_rng(5)
    scans = []
    for k in range(40):
        z = np.array([[100.0 * k, 0.0], [0.0, 90.0 * k]]) + rng.normal(scale=50, size=(2, 2))
        attrs = PlotAttributes.from_columns({
            "flight_level": np.array([300.0 + 0.2 * k, 250.0]),
            "mode_3a": np.array([0o1234, 0o4321]), "address": np.array([0xA1, 0xB2])}, 2)
        keep = rng.random(2) < 0.9
        scans.append(Scan(k, float(k), z[keep], np.zeros(int(keep.sum()), np.int64),
                          np.arange(2 * k, 2 * k + int(keep.sum())), attrs=attrs.take(keep)))
    whole = MHTTracker()
    want = [whole.step(s) for s in scans]
    first = MHTTracker()
    for s in scans[:20]:
        first.step(s)
    first.save(tmp_path / "state.npz")
    again = MHTTracker.load(tmp_path / "state.npz")
    got = [again.step(s) for s in scans[20:]]
    for a, b in zip(want[20:], got, strict=True):
        for f in ("track_id", "x", "y", "plot", "score"):
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f))
    np.testing.assert_array_equal(whole.leaves.level, again.leaves.level)
    np.testing.assert_array_equal(whole.leaves.ident, again.leaves.ident)
    assert np.isfinite(whole.leaves.level[:, 0]).any()


def test_a_mode_s_address_is_evidence_against_clutter_by_hand():
    from mhtrack.mht.attribute_scores import reply_terms

    attrs = PlotAttributes.from_columns({"address": np.array([0xA1, -1, 0xA2])}, 3)
    kappa, lam = np.array([1e-9, 1e-9, 1e-13]), 1.8e-11
    got = reply_terms(M, attrs, kappa, lam)
    # p_S = 0.9, f_S = 1e-3: 0.9 (κ + λ) / (κ f_S + λ p_S)
    assert got[0] == pytest.approx(math.log(0.9 * (1e-9 + lam) / (1e-12 + lam * 0.9)))
    assert got[0] > 3.9  # dense clutter: a reply is strong evidence of a target
    assert got[1] == 0.0  # no address: a position only
    assert abs(got[2]) < 0.01  # κ ≪ λ_v: clutter is no explanation anyway


def test_a_mode_s_track_confirms_no_later():
    """With addresses the same two aircraft's tracks are confirmed no later (online)."""
    def first_rows(attrs_on):
        rng = np.random.default_rng(2)
        trk, first = MHTTracker(), {}
        for k in range(12):
            z = np.array([[100.0 * k, 0.0], [0.0, 2000.0 + 90 * k]]) + rng.normal(
                scale=50, size=(2, 2))
            a = PlotAttributes.from_columns({"address": np.array([0xA1, 0xB2])}, 2) \
                if attrs_on else None
            out = trk.step(Scan(k, float(k), z, np.zeros(2, np.int64),
                                np.arange(2 * k, 2 * k + 2), attrs=a))
            for p in out.plot[out.plot >= 0].tolist():
                first.setdefault(p % 2, k)
        return first
    off, on = first_rows(False), first_rows(True)
    assert set(on) == {0, 1} and all(on[i] <= off.get(i, 99) for i in on)


def test_one_mode_s_plot_may_confirm_on_the_sprt_threshold():
    import dataclasses

    from mhtrack.mht.config import MHTConfig
    from mhtrack.mht.sprt import SPRT
    from mhtrack.mht.tree import Leaves

    sprt = SPRT.from_config(MHTConfig())
    n = 4
    lv = Leaves(np.zeros((n, 4)), np.tile(np.eye(4), (n, 1, 1)),
                np.array([sprt.confirm_threshold + 0.1] * 3 + [sprt.confirm_threshold - 0.1]),
                np.zeros(n), np.arange(n), np.full(n, -1), np.zeros(n, np.int64),
                np.array([1, 1, 2, 1]), np.full((n, 4), -1), np.ones(n, bool),
                np.zeros((n, 0)), np.zeros((n, 0, 4)), np.zeros((n, 0, 4, 4)),
                np.arange(n), np.full(n, -1), np.zeros(n))
    lv = dataclasses.replace(lv, ident=np.array([[-1, 0xA1], [-1, -1], [-1, -1], [-1, 0xA2]]))
    # one plot with an address and a score on the threshold: confirmed; one plot without
    # an address: not (confirm_min_plots = 2); two plots: as before; below: never
    assert sprt.confirms(lv).tolist() == [True, False, True, False]


def test_one_confirmed_track_per_address():
    import dataclasses

    from mhtrack.mht.resume import AddressBook
    from mhtrack.mht.tree import Leaves

    n = 4
    lv = Leaves(np.zeros((n, 4)), np.tile(np.eye(4), (n, 1, 1)), np.ones(n), np.ones(n),
                np.arange(n), np.array([7, -1, -1, -1]), np.zeros(n, np.int64),
                np.full(n, 2), np.full((n, 4), -1), np.ones(n, bool), np.zeros((n, 0)),
                np.zeros((n, 0, 4)), np.zeros((n, 0, 4, 4)), np.arange(n), np.full(n, -1),
                np.zeros(n))
    lv = dataclasses.replace(lv, ident=np.array([[-1, 0xA1], [-1, 0xA1], [-1, 0xB2],
                                                 [-1, -1]]))
    # track 7 carries 0xA1: the tentative tree on 0xA1 waits; the others confirm
    got = AddressBook.one_per_address(lv, np.ones(n, bool))
    assert got.tolist() == [True, False, True, True]
