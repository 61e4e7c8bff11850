"""The history output (``mhtrack.mht.history``): each confirmed track also reported at
the scans before its confirmation, from its first plot."""

import numpy as np
import pytest
from crossing_fixture import same_tracks, simulate
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.build import make_birth
from mhtrack.clutter import KnownClutter
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.history import TentativeHistory
from mhtrack.records import Scan, TrackTable


def _by_hand(cfg: MHTConfig, clutter: KnownClutter) -> MHTTracker:
    """A tracker by hand with the birth its configuration names (the builder's)."""
    return MHTTracker(cfg, clutter, birth=make_birth(cfg, cfg.motion))


def _tracker(sim, **changes) -> MHTTracker:
    return _by_hand(MHTConfig(**changes), KnownClutter(sim.clutter_density))


def test_online_part_of_the_history_is_the_online_output(crossing10):
    hist = _tracker(crossing10).run(crossing10.scans)
    online = _tracker(crossing10).run(crossing10.scans, history=False)
    assert hist.tentative is not None and hist.tentative.any()
    assert same_tracks(hist.online(), online)
    assert not online.tentative.any()
    # ordered by scan, then track id, one row per (scan, track)
    key = hist.scan * 10**6 + hist.track_id
    assert np.all(np.diff(key) > 0)


def test_each_track_is_reported_from_its_first_plot(crossing10):
    trk = _tracker(crossing10)
    hist = trk.run(crossing10.scans)
    online = hist.online()
    plot_scan = {int(r): s.index for s in crossing10.scans for r in s.rows}
    for tid in np.unique(hist.track_id):
        rows = hist.take(hist.track_id == tid)
        confirmed_at = online.scan[online.track_id == tid].min()
        tent = rows.tentative
        # the tentative rows are exactly the scans from the first plot to confirmation − 1
        assert np.array_equal(rows.scan[tent], np.arange(rows.scan[0], confirmed_at))
        assert tent[: tent.sum()].all()
        # the first row holds the tree's root plot, made at that very scan
        assert rows.plot[0] >= 0 and plot_scan[int(rows.plot[0])] == rows.scan[0]
        used = rows.plot[rows.plot >= 0]
        assert all(plot_scan[int(p)] == s for p, s in zip(used, rows.scan[rows.plot >= 0],
                                                          strict=True))


def _one_target(n: int, sigma: float = 50.0, seed: int = 4) -> list[Scan]:
    """One target at 120, −80 m/s, detected every scan, no clutter."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(1, n + 1):
        z = np.array([1000.0 + 120.0 * (k - 1), -500.0 - 80.0 * (k - 1)]) + rng.normal(
            0, sigma, 2)
        out.append(Scan(k, float(k), z[None], np.zeros(1, np.int64), np.array([k - 1])))
    return out


def _textbook_kf(zs: np.ndarray, dt: float, sigma_w: float, sigma_v: float, v_max: float):
    """Filtered states of P1's CV model written out: x = [x, vx, y, vy], one-point
    initialisation with velocity variance (v_max/2)², discrete white-noise acceleration."""
    F = np.array([[1, dt, 0, 0], [0, 1, 0, 0], [0, 0, 1, dt], [0, 0, 0, 1]], float)
    q = np.array([[dt**4 / 4, dt**3 / 2], [dt**3 / 2, dt**2]]) * sigma_v**2
    Q = np.zeros((4, 4))
    Q[:2, :2] = Q[2:, 2:] = q
    H = np.array([[1, 0, 0, 0], [0, 0, 1, 0]], float)
    R = np.eye(2) * sigma_w**2
    x = np.array([zs[0, 0], 0.0, zs[0, 1], 0.0])
    P = np.diag([sigma_w**2, (v_max / 2) ** 2, sigma_w**2, (v_max / 2) ** 2])
    out = [x]
    for z in zs[1:]:
        x, P = F @ x, F @ P @ F.T + Q
        S = H @ P @ H.T + R
        K = P @ H.T @ np.linalg.inv(S)
        x, P = x + K @ (z - H @ x), (np.eye(4) - K @ H) @ P
        out.append(x)
    return np.array(out)


def test_backfilled_states_are_the_filtered_states_of_the_branch():
    """One target without clutter, single CV model: the rows before confirmation equal a
    textbook Kalman filter over the target's plots."""
    scans = _one_target(8)
    cfg = MHTConfig(imm_sigma_v=0.0, sigma_w=50.0, alpha=1e-6)  # confirms late
    trk = _by_hand(cfg, KnownClutter(1e-8))
    hist = trk.run(scans)
    assert set(hist.track_id.tolist()) == {0}
    confirmed_at = hist.scan[~hist.tentative].min()
    assert confirmed_at >= 3, "the test needs a tentative past"
    zs = np.array([s.z[0] for s in scans])
    ref = _textbook_kf(zs, 1.0, cfg.sigma_w, cfg.sigma_v, cfg.v_max)
    est = np.column_stack((hist.x, hist.vx, hist.y, hist.vy))
    np.testing.assert_allclose(est, ref[hist.scan - 1], rtol=1e-9, atol=1e-6)
    assert np.array_equal(hist.scan, np.arange(1, 9)) and np.array_equal(hist.plot,
                                                                          np.arange(8))
    assert np.array_equal(hist.tentative, hist.scan < confirmed_at)


def test_history_depth_bounds_the_backfill():
    scans = _one_target(8)
    cfg = MHTConfig(imm_sigma_v=0.0, sigma_w=50.0, alpha=1e-6)
    full = _by_hand(cfg, KnownClutter(1e-8)).run(scans)
    c = int(full.scan[~full.tentative].min())
    short = MHTTracker(MHTConfig(imm_sigma_v=0.0, sigma_w=50.0, alpha=1e-6, history_scans=1),
                       KnownClutter(1e-8)).run(scans)
    assert np.array_equal(short.scan[short.tentative], [c - 1])
    none = MHTTracker(MHTConfig(imm_sigma_v=0.0, sigma_w=50.0, alpha=1e-6, history_scans=0),
                      KnownClutter(1e-8)).run(scans)
    assert not none.tentative.any() and same_tracks(none, full.online())
    with pytest.raises(ValueError, match="history_scans"):
        MHTConfig(history_scans=-1)
    with pytest.raises(ValueError, match="depth"):
        TentativeHistory(-2)


@pytest.mark.parametrize("cut", [3, 25, 41])
def test_save_restore_keeps_the_tentative_past(crossing40, tmp_path, cut):
    full = _tracker(crossing40).run(crossing40.scans)
    trk = _tracker(crossing40)
    first = trk.run(crossing40.scans[:cut])
    path = tmp_path / "state.npz"
    trk.save(path)
    rest = MHTTracker.load(path).run(crossing40.scans[cut:])
    both = TrackTable.concat([first, rest]).sorted()
    assert same_tracks(both, full)


def test_initiator_birth_backfills_from_the_seed_scan(crossing10):
    trk = _tracker(crossing10, birth="logic")
    hist = trk.run(crossing10.scans)
    online = _tracker(crossing10, birth="logic").run(crossing10.scans, history=False)
    assert same_tracks(hist.online(), online)
    for tid in np.unique(hist.track_id):
        rows = hist.take(hist.track_id == tid)
        t = rows.tentative
        assert np.array_equal(t, np.arange(t.size) < t.sum())  # tentative rows first


@st.composite
def small_scenes(draw):
    """1–3 straight targets with random starts, speeds, detection and clutter, 12 scans
    with random gaps in time."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n_targets = draw(st.integers(1, 3))
    p_d = draw(st.floats(0.5, 1.0))
    clutter = draw(st.floats(0.0, 8.0))
    dts = draw(st.lists(st.floats(0.5, 3.0), min_size=12, max_size=12))
    x0 = rng.uniform(-3000, 3000, (n_targets, 2))
    v = rng.uniform(-150, 150, (n_targets, 2))
    scans, t, row = [], 0.0, 0
    for k, dt in enumerate(dts, start=1):
        t += dt
        z = [x0[i] + v[i] * t + rng.normal(0, 100, 2) for i in range(n_targets)
             if rng.random() < p_d]
        z += list(rng.uniform(-4000, 4000, (rng.poisson(clutter), 2)))
        z = np.asarray(z, float).reshape(-1, 2)
        n = len(z)
        scans.append(Scan(k, t, z, np.zeros(n, np.int64), np.arange(row, row + n)))
        row += n
    return scans, clutter / 8000.0**2 + 1e-9


@settings(max_examples=25, deadline=None)
@given(scene=small_scenes(), depth=st.integers(0, 6))
def test_history_invariants(scene, depth):
    """Whatever the scene: the history's online part is the online output, each track's
    tentative rows come before its first online row on consecutive scans, at most
    ``history_scans`` of them, and no (scan, track) appears twice."""
    scans, kappa = scene
    cfg = MHTConfig(history_scans=depth)
    hist = _by_hand(cfg, KnownClutter(kappa)).run(scans)
    online = _by_hand(cfg, KnownClutter(kappa)).run(scans, history=False)
    assert same_tracks(hist.online(), online)
    key = hist.scan * 10**6 + hist.track_id
    assert np.all(np.diff(key) > 0)
    used = hist.plot >= 0  # no plot given to two tracks at one scan
    assert len(np.unique(hist.scan[used] * 10**9 + hist.plot[used])) == used.sum()
    index = {s.index: i for i, s in enumerate(scans)}
    for tid in np.unique(hist.track_id):
        rows = hist.take(hist.track_id == tid)
        t = rows.tentative
        n = int(t.sum())
        assert n <= depth and t[:n].all() and not t[n:].any()
        if n:
            pos = np.array([index[int(s)] for s in rows.scan[: n + 1]])
            assert np.array_equal(np.diff(pos), np.ones(n, int))


@pytest.mark.parametrize(("seed", "clutter", "birth"),
                         [(4, 40.0, "every-plot"), (5, 10.0, "logic")])
def test_no_plot_is_given_to_two_tracks_at_a_scan(seed, clutter, birth):
    """An old tentative past can hold plots of a track that has since ended (the best
    hypothesis keeps plots apart only within its window); the backfill stops before them.
    These two draws had such clashes before (plots 482, 511, 583 at scans 12–14; plot 1063
    at scan 86)."""
    sim = simulate(clutter_rate=clutter, seed=seed)
    trk = _by_hand(MHTConfig(birth=birth), KnownClutter(sim.clutter_density))
    hist = trk.run(sim.scans)
    used = hist.plot >= 0
    pairs = np.column_stack((hist.scan[used], hist.plot[used]))
    assert len(np.unique(pairs, axis=0)) == len(pairs)
    online = _by_hand(MHTConfig(birth=birth), KnownClutter(sim.clutter_density)).run(
        sim.scans, history=False)
    assert same_tracks(hist.online(), online)
