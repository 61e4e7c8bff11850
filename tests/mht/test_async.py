"""The MHT on asynchronous plots: frames of rotating radars, per-leaf times and P_D."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from async_fixture import Radar, polar_plot, sensor_set, simulate_async

from mhtrack.clutter.gmm import GMMClutter
from mhtrack.clutter.known import KnownClutter
from mhtrack.clutter.per_sensor import PerSensorClutter
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.coverage import RadarCoverage
from mhtrack.models.imm import CVModelSet
from mhtrack.models.motion import ConstantVelocity, States
from mhtrack.records import PlotTable, Scan

CFG = MHTConfig(new_target_density=1e-12, imm_sigma_v=0.0)


def _async_tracker(sim, cfg=CFG, clutter=None):
    per = {s.id: s.period for s in sim.sensors.sensors}
    clutter = PerSensorClutter(GMMClutter, per) if clutter is None else clutter
    return MHTTracker(cfg, clutter, coverage=RadarCoverage(sim.sensors))


def _assess(sim, tracks):
    """Per confirmed track, the target it follows (median distance < 500 m) or -1."""
    on = tracks.online()
    out = {}
    for tid in np.unique(on.track_id).tolist():
        r = on.take(on.track_id == tid)
        truth = np.array([sim.truth_at(t) for t in r.time])
        d = np.median(np.hypot(truth[:, :, 0] - r.x[:, None], truth[:, :, 1] - r.y[:, None]),
                      axis=0)
        out[tid] = int(d.argmin()) if d.min() < 500.0 else -1
    return out


@pytest.mark.parametrize("motion", [ConstantVelocity(5.0), CVModelSet((1.0, 10.0), 50.0)])
def test_per_row_prediction_equals_row_by_row(motion):
    rng = np.random.default_rng(0)
    n, r = 5, motion.n_models
    x = rng.normal(0, 100, (n, 4))
    A = rng.normal(0, 1, (n, 4, 4))
    P = A @ np.swapaxes(A, 1, 2) + np.eye(4)
    mu = np.full((n, r), 1.0 / r) if r else np.zeros((n, 0))
    st = States(x, P, np.repeat(x[:, None], r, 1), np.repeat(P[:, None], r, 1), mu)
    dt = np.array([0.5, 1.0, 2.5, -0.3, 4.0])
    both = motion.predict(st, dt)
    for i in range(n):
        one = motion.predict(st.take(np.array([i])), float(dt[i]) if dt[i] >= 0 else dt[i:i + 1])
        np.testing.assert_allclose(both.x[i], one.x[0], rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(both.P[i], one.P[0], rtol=1e-12, atol=1e-9)


def _polar_scan(index, radar, plots):
    """A frame of ``radar``: ``plots`` = [(time, range, bearing_deg)]."""
    t = np.array([p[0] for p in plots])
    z, R = polar_plot(radar, np.array([p[1] for p in plots]), np.array([p[2] for p in plots]))
    return Scan(index, float(t.max()), z, np.full(len(t), radar.id, np.int64),
                np.arange(len(t), dtype=np.int64) + 10 * index, R, None, t)


def test_hand_worked_four_frames():
    """One radar (period 8 s, ω = 45°/s, P_D 0.8) and plots 10 km away, frames sweeping
    [0°, 10°] (P1 at 0°, P2 at 10°), (10°, 100°] (P3 at 100°), (100°, 250°] and
    (250°, 390°] (P4 at 250°, P5 at 30°, both 40 km away: new trees only).

    Frame 1: the tree of P1 is not swept (unchanged); P2's lies on the sector's start
    edge — looked at, not certainly: its miss costs ``ln(1 − 0) = 0``. Frame 2: the trees
    of P1 and P2 are not swept (unchanged), P3's lies on the start edge (miss costs 0).
    Frame 3 sweeps across P1's and P2's trees: each misses, ``ΔL = ln(1 − 0.8)``; P3's
    tree is not swept: carried unchanged (state, time, score, window)."""
    radar = Radar(1, 0.0, 0.0, period=8.0, phase_deg=0.0, pd=0.8, max_range=100_000.0)
    lam, kappa = 1e-9, 1e-9
    cfg = MHTConfig(new_target_density=lam, imm_sigma_v=0.0)
    trk = MHTTracker(cfg, KnownClutter(kappa), coverage=RadarCoverage(sensor_set([radar])))
    L0 = math.log(lam * 0.8 / (kappa + lam))
    miss = math.log(1 - 0.8)
    w = 45.0

    def trees():
        lv = trk.leaves
        return {int(t): lv.take(lv.tree == t) for t in np.unique(lv.tree)}

    trk.step(_polar_scan(0, radar, [(0.0, 10_000.0, 0.0), (10 / w, 10_000.0, 10.0)]))
    np.testing.assert_allclose(trk.leaves.score, [L0, L0], rtol=1e-12)
    np.testing.assert_allclose(trk.leaves.time, [0.0, 10 / w])
    t0 = trees()[0]
    trk.step(_polar_scan(1, radar, [(100 / w, 10_000.0, 100.0)]))
    tr = trees()
    np.testing.assert_allclose(tr[1].score, [L0], rtol=1e-12)
    np.testing.assert_allclose(tr[1].time, [100 / w])
    t1 = tr[1]
    trk.step(_polar_scan(2, radar, [(250 / w, 40_000.0, 250.0)]))
    tr = trees()
    np.testing.assert_allclose(tr[2].score, [L0], rtol=1e-12)
    np.testing.assert_allclose(tr[2].time, [250 / w])
    t2 = tr[2]
    for before, after in ((t0, tr[0]), (t1, tr[1])):
        for f in ("x", "P", "score", "time", "window", "node"):
            np.testing.assert_array_equal(getattr(after, f), getattr(before, f))
    trk.step(_polar_scan(3, radar, [(390 / w, 40_000.0, 30.0)]))
    tr = trees()
    np.testing.assert_allclose(tr[0].score, [L0 + miss], rtol=1e-12)
    np.testing.assert_allclose(tr[1].score, [L0 + miss], rtol=1e-12)
    np.testing.assert_allclose(tr[0].time, [390 / w])
    for f in ("x", "P", "score", "time", "window", "node"):
        np.testing.assert_array_equal(getattr(tr[2], f), getattr(t2, f))


def test_plots_at_the_frame_time_give_the_synchronous_result(crossing10):
    """Timed frames whose plots all carry the frame's time are synchronous scans."""
    cfg = MHTConfig()
    a = MHTTracker(cfg, KnownClutter(crossing10.clutter_density))
    b = MHTTracker(cfg, KnownClutter(crossing10.clutter_density))
    for scan in crossing10.scans[:40]:
        out_a = a.step(scan)
        out_b = b.step(dataclasses.replace(scan, t=np.full(len(scan), float(scan.time))))
        for f in ("track_id", "x", "y", "vx", "vy", "plot", "score", "time"):
            np.testing.assert_array_equal(getattr(out_a, f), getattr(out_b, f))


@pytest.fixture(scope="module")
def two_radars():
    return simulate_async(seed=1)


def test_two_radars_confirm_all_targets_and_no_false_track(two_radars):
    trk = _async_tracker(two_radars)
    match = _assess(two_radars, trk.run(two_radars.plots))
    assert set(match.values()) - {-1} == set(range(5))
    assert -1 not in match.values()


def test_permuting_sensor_ids_gives_the_same_tracks(two_radars):
    sim = two_radars
    radars = [Radar(7, -15_000.0, -5_000.0, period=4.0, phase_deg=10.0),
              Radar(3, 20_000.0, 10_000.0, period=6.0, phase_deg=200.0, pd=0.85,
                    sigma_range=60.0, sigma_bearing_deg=0.2)]
    relabel = {1: 7, 2: 3}
    p = sim.plots
    q = dataclasses.replace(p, sensor=np.array([relabel[int(s)] for s in p.sensor]))
    sim2 = dataclasses.replace(sim, plots=q, sensors=sensor_set(radars))
    a = _async_tracker(sim).run(p).online()
    b = _async_tracker(sim2).run(q).online()
    ka = np.lexsort((a.y, a.x, a.time))
    kb = np.lexsort((b.y, b.x, b.time))
    for f in ("time", "x", "y", "plot"):
        np.testing.assert_array_equal(getattr(a, f)[ka], getattr(b, f)[kb])


def test_save_restore_mid_stream_is_bit_identical(two_radars, tmp_path):
    sim = two_radars
    scans = list(sim.plots.scans())
    ref = _async_tracker(sim)
    expected = [ref.step(s) for s in scans]
    trk = _async_tracker(sim)
    for s in scans[:150]:
        trk.step(s)
    trk.save(tmp_path / "state.npz")
    per = {s.id: s.period for s in sim.sensors.sensors}
    back = MHTTracker.load(tmp_path / "state.npz", PerSensorClutter(GMMClutter, per),
                           coverage=RadarCoverage(sim.sensors))
    for s, want in zip(scans[150:], expected[150:], strict=True):
        got = back.step(s)
        for f in ("track_id", "x", "y", "P", "score", "time", "plot"):
            np.testing.assert_array_equal(getattr(got, f), getattr(want, f))


def test_same_input_same_output(two_radars):
    a = _async_tracker(two_radars).run(two_radars.plots)
    b = _async_tracker(two_radars).run(two_radars.plots)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.track_id, b.track_id)


def test_timed_table_is_stepped_frame_by_frame(two_radars):
    p: PlotTable = two_radars.plots
    scans = list(p.scans())
    assert len(scans) == p.n_scans
    assert all(np.unique(s.sensor).size == 1 for s in scans)
