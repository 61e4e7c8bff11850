"""Rotating radars: beam-crossing times, geodesic range/bearing, noise, P_D, clutter.

Independent facts: GeographicLib's ``WGS84.Inverse`` for the true range and
azimuth; the closed-form crossing times of a stationary target; the beam's bearing at a
plot's time; binomial and Poisson statistics."""

import numpy as np
import pytest
from geodesic_reference import WGS84

from mhtrack.frames import frame_lengths
from mhtrack.models.geodesy import LocalFrame, polar_to_local
from mhtrack.scenario import from_dict, simulate
from mhtrack.scenario.trajectory import Segment

SITE = (47.3, 8.4)
ORIGIN = (47.0, 8.0)
TINY_R, TINY_B = 1e-9, 1e-12  # "noise off": sigmas must be > 0


def scenario(targets, *, period=2.0, phase=30.0, pd=1.0, sr=TINY_R, sb=TINY_B,
             clutter_rate=0.0, patches=(), scans=(0, 100), T=1.0, max_range=200e3,
             truth_dt=1.0):
    return from_dict({
        "T": T, "scans": list(scans), "truth_dt": truth_dt,
        "region": {"xmin": -3e5, "xmax": 3e5, "ymin": -3e5, "ymax": 3e5},
        "origin": {"lat": ORIGIN[0], "lon": ORIGIN[1]},
        "sensors": [{"kind": "polar", "id": 1, "lat": SITE[0], "lon": SITE[1],
                     "sigma_range": sr, "sigma_bearing_deg": sb, "pd": pd, "period": period,
                     "phase": phase, "max_range": max_range, "clutter_rate": clutter_rate,
                     "clutter_patches": list(patches)}],
        "targets": targets,
    })


def geodesic(lat, lon):
    """(range m, azimuth deg in [0, 360)) from SITE by GeographicLib."""
    out = [WGS84.Inverse(SITE[0], SITE[1], a, b) for a, b in zip(lat, lon, strict=True)]
    return (np.array([g["s12"] for g in out]), np.array([g["azi1"] for g in out]) % 360.0)


MOVING = [
    {"id": 1, "state": [30_000.0, 250.0, 80_000.0, -40.0], "birth": 0, "death": 100},
    {"id": 2, "state": [-60_000.0, -100.0, -20_000.0, 230.0], "birth": 10, "death": 90},
    {"id": 3, "state": [45_000.0, 0.0, 40_000.0, 260.0], "birth": 0, "death": 100},  # passes 5 km
]


def test_plot_bearing_is_the_beams_at_the_plot_time_and_geodesic_truth():
    sc = scenario(MOVING, period=4.0, phase=123.0)
    sim = simulate(sc, seed=3)
    p = sim.plots
    radar = sc.sensors[0]
    assert p.timed and len(p) > 0 and (p.origin >= 0).all()
    beam = radar.phase + 360.0 * p.time / radar.period
    assert np.abs((p.bearing - beam + 180) % 360 - 180).max() < 1e-6
    # the true position at the plot's own time (constant velocity, closed form)
    frame = LocalFrame(*ORIGIN)
    state = {t["id"]: (np.array(t["state"]), t["birth"]) for t in MOVING}
    xy = np.array([state[o][0][[0, 2]] + state[o][0][[1, 3]] * (t - state[o][1])
                   for o, t in zip(p.origin.tolist(), p.time.tolist(), strict=True)])
    lat, lon = frame.to_geodetic(xy[:, 0], xy[:, 1])
    r, b = geodesic(lat, lon)
    assert np.abs(p.range - r).max() < 1e-3
    assert np.abs((p.bearing - b + 180) % 360 - 180).max() < 1e-7
    # one plot per target per rotation while alive (P_D = 1, all within max_range)
    for tid, (_, birth) in state.items():
        n = int((p.origin == tid).sum())
        alive = (90 if tid == 2 else 100) - birth
        assert abs(n - alive / radar.period) <= 1
    # x, y, R: the site's polar plots converted on the ellipsoid
    z, R = polar_to_local(frame, *SITE, p.range, p.bearing, radar.sigma_range,
                          radar.sigma_bearing_deg)
    np.testing.assert_array_equal(p.x, z[:, 0])
    np.testing.assert_array_equal(p.R, R)


def test_stationary_target_crossing_times_closed_form():
    sc = scenario([{"id": 5, "state": [-20_000.0, 0.0, 50_000.0, 0.0]}], period=3.0,
                  phase=250.0, scans=(0, 60))
    p = simulate(sc, seed=0).plots
    lat, lon = LocalFrame(*ORIGIN).to_geodetic(-20_000.0, 50_000.0)
    _, b = geodesic([lat], [lon])
    first = ((b[0] - 250.0) % 360.0) / 120.0  # ω = 120°/s
    expected = first + 3.0 * np.arange(20)
    expected = expected[expected <= 60.0]
    np.testing.assert_allclose(p.time, expected, atol=1e-9, rtol=0)


def test_rows_sorted_by_frame_then_time_one_sensor_per_frame():
    sc = scenario(MOVING, period=4.0, clutter_rate=30.0)
    p = simulate(sc, seed=1).plots
    assert (np.diff(p.scan) >= 0).all()
    same = p.scan[1:] == p.scan[:-1]
    assert (np.diff(p.time)[same] >= 0).all()
    span = frame_lengths({1: 4.0})[1]
    for k in np.unique(p.scan):
        t = p.time[p.scan == k]
        assert t.max() - t.min() <= span + 1e-12


def test_noise_statistics_match_sigmas():
    targets = [{"id": i, "state": [x, 0.0, y, 0.0]}
               for i, (x, y) in enumerate([(50e3, 10e3), (-30e3, 70e3), (10e3, -90e3),
                                           (120e3, 40e3), (-80e3, -60e3)], 1)]
    sr, sb = 60.0, 0.15
    sc = scenario(targets, period=1.0, sr=sr, sb=sb, scans=(0, 400))
    p = simulate(sc, seed=7).plots
    frame = LocalFrame(*ORIGIN)
    xy = {t["id"]: (t["state"][0], t["state"][2]) for t in targets}
    lat, lon = frame.to_geodetic(*np.array([xy[o] for o in p.origin.tolist()]).T)
    r, b = geodesic(lat, lon)
    dr, db = p.range - r, (p.bearing - b + 180) % 360 - 180
    n = len(p)
    assert n > 1900
    assert abs(dr.mean()) < 4 * sr / np.sqrt(n) and abs(db.mean()) < 4 * sb / np.sqrt(n)
    # sample sd within 4 standard errors (sd / sqrt(2n))
    assert abs(dr.std() / sr - 1) < 4 / np.sqrt(2 * n)
    assert abs(db.std() / sb - 1) < 4 / np.sqrt(2 * n)


def test_detection_rate_is_pd_and_max_range_is_respected():
    targets = [{"id": 1, "state": [20e3, 0.0, 30e3, 0.0]},
               {"id": 2, "state": [0.0, 0.0, -150e3, 0.0]}]  # ~185 km from the site
    sc = scenario(targets, period=1.0, pd=0.7, scans=(0, 1000), max_range=150e3)
    p = simulate(sc, seed=11).plots
    n_look = 1000  # one crossing per rotation over 1000 s
    k = int((p.origin == 1).sum())
    assert abs(k - 0.7 * n_look) < 4 * np.sqrt(n_look * 0.7 * 0.3)
    assert not (p.origin == 2).any()


def test_clutter_poisson_per_rotation_uniform_in_range_azimuth():
    rate, period, rmax = 15.0, 1.0, 100e3
    sc = scenario([], period=period, phase=0.0, clutter_rate=rate, scans=(0, 2000),
                  max_range=rmax)
    p = simulate(sc, seed=2).plots
    assert (p.origin == -1).all()
    # phase 0: rotation n is [n, n + 1) s, and every plot is timed by its azimuth
    np.testing.assert_allclose(p.bearing, (p.time % period) * 360.0 / period, atol=1e-9)
    counts = np.bincount(np.floor(p.time / period).astype(int), minlength=2000)[:2000]
    n = counts.size
    assert abs(counts.mean() - rate) < 4 * np.sqrt(rate / n)
    # Poisson: variance = mean (sd of the sample variance ≈ sqrt(2/n)·λ)
    assert abs(counts.var() / rate - 1) < 4 * np.sqrt(2 / n)
    # uniform range on [0, rmax] and azimuth on [0, 360): mean and sd of a uniform
    m = len(p)
    assert abs(p.range.mean() - rmax / 2) < 4 * rmax / np.sqrt(12 * m)
    assert abs(p.range.std() - rmax / np.sqrt(12)) < 0.02 * rmax
    assert abs(p.bearing.mean() - 180.0) < 4 * 360 / np.sqrt(12 * m)


def test_clutter_patch_is_a_gaussian_clump():
    patch = {"range": 40e3, "bearing": 300.0, "sigma_range": 2e3, "sigma_bearing_deg": 3.0,
             "rate": 5.0}
    sc = scenario([], period=1.0, patches=[patch], scans=(0, 1000))
    p = simulate(sc, seed=4).plots
    n = len(p)
    assert abs(n / 1000 - 5.0) < 4 * np.sqrt(5.0 / 1000)
    assert abs(p.range.mean() - 40e3) < 4 * 2e3 / np.sqrt(n)
    assert abs(p.range.std() / 2e3 - 1) < 4 / np.sqrt(2 * n)
    assert abs(p.bearing.mean() - 300.0) < 4 * 3.0 / np.sqrt(n)


def test_truth_every_truth_dt_on_the_exact_line():
    sc = scenario(MOVING, scans=(0, 100), T=1.0, truth_dt=2.5)
    tr = simulate(sc, seed=0).truth
    assert set(np.unique(tr.time).tolist()) <= set((2.5 * np.arange(41)).tolist())
    np.testing.assert_array_equal(tr.time, 2.5 * tr.scan)
    for t in MOVING:
        m = tr.target_id == t["id"]
        s = np.array(t["state"])
        times = tr.time[m]
        assert times.min() >= t["birth"] and times.max() <= t["death"]
        np.testing.assert_allclose(tr.x[m], s[0] + s[1] * (times - t["birth"]), atol=1e-6)
        np.testing.assert_allclose(tr.vy[m], s[3], atol=1e-9)


def test_hermite_segment_meets_grid_states():
    t = np.array([0.0, 10.0, 20.0])
    p = np.array([[0.0, 0.0], [2000.0, 500.0], [4500.0, 500.0]])
    v = np.array([[200.0, 60.0], [230.0, 0.0], [250.0, -20.0]])
    seg = Segment(1, t, p, v)
    pos, vel = seg.state(t)
    np.testing.assert_allclose(pos, p, atol=1e-9)
    np.testing.assert_allclose(vel, v, atol=1e-9)
    # velocity is the derivative of the position (central difference)
    tt = np.array([3.0, 14.0])
    d = (seg.state(tt + 1e-4)[0] - seg.state(tt - 1e-4)[0]) / 2e-4
    np.testing.assert_allclose(seg.state(tt)[1], d, rtol=1e-6)


def test_same_seed_same_output_other_seed_differs():
    sc = scenario(MOVING, period=4.0, pd=0.8, sr=40.0, sb=0.1, clutter_rate=10.0)
    a, b, c = simulate(sc, seed=5), simulate(sc, seed=5), simulate(sc, seed=6)
    for name in ("scan", "time", "sensor", "range", "bearing", "origin", "x", "y", "R"):
        np.testing.assert_array_equal(getattr(a.plots, name), getattr(b.plots, name))
    assert len(a.plots) != len(c.plots) or not np.array_equal(a.plots.range, c.plots.range)


def test_dict_round_trip_and_errors():
    sc = scenario(MOVING, patches=[{"range": 1e4, "bearing": 5.0, "sigma_range": 1e3,
                                    "sigma_bearing_deg": 2.0, "rate": 1.0}])
    assert from_dict(sc.to_dict()) == sc
    d = sc.to_dict()
    del d["sensors"][0]["lat"]
    with pytest.raises(ValueError, match=r"sensors\[0\]\.lat: missing"):
        from_dict(d)
    d = sc.to_dict()
    d["sensors"].append({"kind": "cartesian", "id": 2, "sigma": 10.0, "pd": 0.9})
    with pytest.raises(ValueError, match=r"sensors\[1\]: a cartesian sensor without a period"):
        from_dict(d)
    d = sc.to_dict()
    d["sensors"][0]["clutter_patches"][0]["rate"] = -1.0
    with pytest.raises(ValueError, match=r"sensors\[0\]\.clutter_patches\[0\]\.rate"):
        from_dict(d)
    d = sc.to_dict()
    d["clutter"] = {"kind": "uniform", "rate": 3.0}
    with pytest.raises(ValueError, match=r"clutter\.rate: rotating radars"):
        from_dict(d)


def test_sensor_set_round_trips_through_a_sensors_file(tmp_path):
    from mhtrack.io.sensors import read_sensors, write_sensors

    sc = scenario(MOVING, period=6.0, pd=0.8)
    ss = sc.sensor_set()
    assert ss.origin == ORIGIN
    s = ss.sensor(1)
    assert (s.kind, s.lat, s.lon, s.period, s.pd, s.max_range) == ("polar", *SITE, 6.0, 0.8,
                                                                    200e3)
    write_sensors(ss, tmp_path / "s.toml")
    assert read_sensors(tmp_path / "s.toml") == ss


def test_example_toml_loads_and_simulates():
    from pathlib import Path

    from mhtrack.scenario import load_scenario

    path = Path(__file__).parents[2] / "docs" / "examples" / "rotating-pair.toml"
    sc = load_scenario(path)
    assert sc.rotating and [s.period for s in sc.sensors] == [6.0, 10.0]
    sim = simulate(sc, seed=1)
    assert set(np.unique(sim.plots.origin[sim.plots.origin >= 0])) == {1, 2, 3}
