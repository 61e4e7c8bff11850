"""The defaults of timed plots from rotating radars (build.radar_rule): against values
worked by hand, the learned reach against a known ring of plots, and the printed rule
naming the radars; scan inputs keep P1's area rule."""

import math

import numpy as np
import pyarrow.csv as pacsv
import pytest
from click.testing import CliRunner

from mhtrack.build import misses_to_delete, radar_rule
from mhtrack.cli.main import cli
from mhtrack.mht.reach import ReachEstimator
from mhtrack.models.radars import RadarSensor, SensorSet

ORIGIN = (46.8, 8.2)


def radar(sid, period=10.0, max_range=100e3, pd=0.9, position=(0.0, 0.0)):
    return RadarSensor(sid, "polar", pd=pd, position=position, sigma_range=50.0,
                       sigma_bearing_deg=0.1, period=period, max_range=max_range)


def ring(n_rot, per_rot, period, r, rng):
    """``per_rot`` plots a rotation at range ``r`` and random bearings, evenly timed over
    each of ``n_rot`` rotations (so they fall in exactly ``n_rot`` rotations)."""
    t = (np.repeat(np.arange(n_rot), per_rot)
         + np.tile((np.arange(per_rot) + 0.5) / per_rot, n_rot)) * period
    b = rng.uniform(0, 2 * np.pi, t.size)
    return t, r * np.sin(b), r * np.cos(b)


def test_one_radar_with_max_range_against_hand_worked_values():
    # 100 plots, one a second from 0 to 99 s, of a 10 s radar reaching 100 km:
    # K = 10 rotations, 10 plots a rotation, A = π·1e10 = 3.14159e10 m²,
    # ρ = 10 / 3.14159e10 = 3.18310e-10 per m² per look,
    # D = (π/2)·100 km / 300 m/s = 523.599 s, λ = ρ·10/523.599 = 6.07927e-12.
    t = np.arange(100.0)
    x, y = np.full(100, 10e3), np.zeros(100)
    rule = radar_rule(SensorSet(ORIGIN, (radar(1),)), np.ones(100, int), t, x, y, v_max=300.0)
    (r,) = rule.radars
    assert r.plots_per_rotation == pytest.approx(10.0)
    assert r.reach == pytest.approx(100e3)
    assert r.density == pytest.approx(3.18310e-10, rel=1e-5)
    assert r.crossing_s(300.0) == pytest.approx(523.599, rel=1e-6)
    assert rule.new_target_density == pytest.approx(6.07927e-12, rel=1e-5)
    assert rule.clutter_density == pytest.approx(3.18310e-10, rel=1e-5)
    assert not r.learned
    # a 13 h gap in the middle (the recording paused) adds no rotation: same figures
    gap = np.where(t >= 50, t + 13 * 3600.0, t)
    again = radar_rule(SensorSet(ORIGIN, (radar(1),)), np.ones(100, int), gap, x, y,
                       v_max=300.0)
    assert again.new_target_density == rule.new_target_density


def test_the_median_over_three_radars():
    # same plots a rotation and reach, periods 4, 10, 12 s: λ ∝ T, the median is the 10 s
    # radar's; ρ is the same for all three
    rng = np.random.default_rng(0)
    parts = [ring(10, 20, p, 50e3, rng) for p in (4.0, 10.0, 12.0)]
    sensor = np.concatenate([np.full(200, i + 1) for i in range(3)])
    t, x, y = (np.concatenate([p[k] for p in parts]) for k in range(3))
    sensors = SensorSet(ORIGIN, tuple(radar(i + 1, p) for i, p in enumerate((4., 10., 12.))))
    rule = radar_rule(sensors, sensor, t, x, y, v_max=300.0)
    lam = [r.new_target_density(300.0) for r in rule.radars]
    assert lam[0] < lam[1] < lam[2]
    assert rule.new_target_density == lam[1]
    # each: 200 plots over 10 rotations, 20 a rotation over π·(100 km)²
    for r in rule.radars:
        assert r.density == pytest.approx(20 / (math.pi * 1e10))


def test_reach_learned_from_a_ring_of_plots():
    # no max_range: the plots lie on a 60 km ring in every sector, every rotation, so the
    # learned reach is 60 km and the area π·(60 km)²
    rng = np.random.default_rng(1)
    t, x, y = ring(30, 200, 5.0, 60e3, rng)
    s = SensorSet(ORIGIN, (radar(3, period=5.0, max_range=None),))
    rule = radar_rule(s, np.full(t.size, 3), t, x, y, v_max=250.0)
    (r,) = rule.radars
    assert r.learned
    assert r.reach == pytest.approx(60e3)
    assert r.area == pytest.approx(math.pi * 60e3**2)


def test_learned_area_is_the_online_estimators_envelope_over_the_whole_input():
    # the tracker's own ReachEstimator, given a memory as long as the input, learns the
    # same per-sector reach: random ranges and bearings, some sectors left empty
    rng = np.random.default_rng(2)
    t = np.sort(rng.uniform(0, 300, 3000))
    b = rng.uniform(0, 300, t.size)  # degrees: 300–360 stays empty
    r = rng.uniform(1e3, 2e5, t.size)
    x, y = r * np.sin(np.radians(b)), r * np.cos(np.radians(b))
    s = SensorSet(ORIGIN, (radar(4, period=6.0, max_range=None),))
    est = ReachEstimator({4: 6.0}, memory=400.0)
    est.update(4, t, r, b)
    want = math.pi * np.mean(est.envelope(4) ** 2)
    (got,) = radar_rule(s, np.full(t.size, 4), t, x, y, v_max=300.0).radars
    assert got.area == pytest.approx(want, rel=1e-9)


def test_no_rotating_radar_no_rule():
    s = SensorSet(ORIGIN, (radar(1, period=None),))
    t = np.linspace(0, 10, 20)
    assert radar_rule(s, np.ones(20, int), t, t, t, v_max=300.0) is None
    assert radar_rule(None, None, None, None, None, v_max=300.0) is None


@pytest.mark.parametrize(("pd", "k"), [(0.9, 4), (0.95, 4), (0.85, 5), (0.5, 14)])
def test_misses_to_delete(pd, k):
    # ln(1e-4 / 0.98) = -9.190; ln(0.1) = -2.303 → 3.99; ln(0.05) = -2.996 → 3.07;
    # ln(0.15) = -1.897 → 4.84; ln(0.5) = -0.693 → 13.26
    assert misses_to_delete(pd, 0.02, 1e-4) == k


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    d = tmp_path_factory.mktemp("rr") / "sim"
    r = CliRunner().invoke(cli, ["simulate", "opensky-radars", "--seed", "1", "--scans", "40",
                                 "--out", str(d)])
    assert r.exit_code == 0, r.output
    return d


def test_track_prints_the_rule_naming_the_radars(sim, tmp_path):
    r = CliRunner().invoke(cli, ["track", str(sim / "plots.csv"), "--sensors",
                                 str(sim / "sensors.toml"), "--out", str(tmp_path / "t.csv")])
    assert r.exit_code == 0, r.output
    # radar 1 by hand from the plots file: plots over the 4 s rotations holding them,
    # over π·(300 km)²
    p = pacsv.read_csv(sim / "plots.csv")
    t = p["time"].to_numpy()[p["sensor"].to_numpy() == 1]
    per_rot = t.size / np.unique((t - t.min()) // 4.0).size
    rho = per_rot / (math.pi * 300e3**2)
    for sid, period in ((1, 4), (2, 10), (3, 12)):
        assert f"radar {sid} ({period} s, reach 300 km max_range" in r.stdout
    assert f"{per_rot:.3g} plots a rotation: ρ {rho:.3g}" in r.stdout
    assert "per m² per look" in r.stdout and "bounding box" not in r.stdout


def test_scans_keep_p1s_area_rule(tmp_path):
    r = CliRunner().invoke(cli, ["run", "crossing", "--seed", "1", "--scans", "10", "--out",
                                 str(tmp_path / "run")])
    assert r.exit_code == 0, r.output
    (tmp_path / "alone").mkdir()
    (tmp_path / "alone" / "plots.csv").write_bytes((tmp_path / "run" / "plots.csv").read_bytes())
    r = CliRunner().invoke(cli, ["track", str(tmp_path / "alone" / "plots.csv"), "--out",
                                 str(tmp_path / "t.csv")])
    assert r.exit_code == 0, r.output
    assert "new targets per scan over the plots'" in r.stdout and "radar" not in r.stdout


def test_pipeline_takes_the_rule_and_the_user_overrides_it(sim):
    from mhtrack.pipeline import Pipeline, TrackOptions

    plots, sensors = str(sim / "plots.csv"), str(sim / "sensors.toml")
    pipe = Pipeline.open(plots, TrackOptions(tracker="mht"), sensors_file=sensors)
    rule = pipe.choices.radars
    assert [r.sensor for r in rule.radars] == [1, 2, 3]
    assert pipe.config.new_target_density == rule.new_target_density
    # --tracker mht: the known κ is the median plot density per look, and the note says so
    assert pipe.tracker.clutter.estimator(2).kappa == rule.clutter_density
    assert f"clutter κ = {rule.clutter_density:.4g} per m² per look" in pipe.birth_note
    given = Pipeline.open(plots, TrackOptions(tracker="mht", new_target_density=1e-9,
                                              clutter_density=3e-9), sensors_file=sensors)
    assert given.config.new_target_density == 1e-9
    assert given.tracker.clutter.estimator(2).kappa == 3e-9
    assert given.birth_note is None
