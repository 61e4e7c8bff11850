"""Clutter scenes in a rotating-radar simulation: the plots each radar draws against the
integral of the true intensity the metrics use (over many seeded runs, per polar cell),
the named scenes' layout in closed form, seeded determinism, the random streams, and the
TOML form."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.stats import poisson

from mhtrack.scenario import Scenario, preset, simulate
from mhtrack.scenario.scene_truth import RadarTruth
from mhtrack.scenario.scenes import SCENES, WIND, clutter_scene, with_clutter_scene
from mhtrack.scenario.sweep import rotation_middle

SCANS = 41  # 0 … 40 s: radar 1 (4 s) turns 10 times, radar 2 (6 s, phase 90°) 5 full times


def _storm() -> Scenario:
    return with_clutter_scene(preset("radars-clutter", scans=SCANS), "storm")


def _cell_mass(truth: RadarTruth, sid: int, t: float, r0: float, r1: float, b0: float,
               b1: float, n: int = 120) -> float:
    """∫ κ_s(x, t) dA over a polar cell about the radar's site, midpoint rule in (r, θ)."""
    site = truth.site(sid)
    r = r0 + (r1 - r0) * (np.arange(n) + 0.5) / n
    th = np.radians(b0 + (b1 - b0) * (np.arange(n) + 0.5) / n)
    R, TH = np.meshgrid(r, th)
    xy = np.column_stack((site[0] + (R * np.sin(TH)).ravel(),
                          site[1] + (R * np.cos(TH)).ravel()))
    dA = (r1 - r0) / n * math.radians(b1 - b0) / n
    return float((truth.intensity(sid, t, xy) * R.ravel()).sum() * dA)


def test_clutter_counts_per_polar_cell_match_the_true_intensity():
    sc = _storm()
    radar = {s.id: s for s in sc.sensors}
    truth = RadarTruth(sc)
    # (sensor, r0, r1, b0, b1): ground, the burst's sector, the sea band, open country
    cells = [(1, 1000.0, 6000.0, 0.0, 120.0), (1, 10_000.0, 40_000.0, 60.0, 80.0),
             (2, 24_000.0, 36_000.0, 150.0, 240.0), (2, 10_000.0, 45_000.0, 300.0, 360.0)]
    seeds = range(25)
    observed = np.zeros(len(cells))
    for seed in seeds:
        p = simulate(sc, seed=seed).plots
        clutter = p.origin < 0
        for i, (sid, r0, r1, b0, b1) in enumerate(cells):
            rot = radar[sid]
            full = p.time < 40.0 if rot.period == 4.0 else (p.time >= 4.5) & (p.time < 34.5)
            observed[i] += np.count_nonzero(
                clutter & full & (p.sensor == sid) & (p.range >= r0) & (p.range < r1)
                & (p.bearing >= b0) & (p.bearing < b1))
    starts = {1: 4.0 * np.arange(10), 2: 4.5 + 6.0 * np.arange(5)}  # beam at north
    expected = np.array([
        len(seeds) * sum(_cell_mass(truth, sid, float(t0) + 0.1, r0, r1, b0, b1)
                         for t0 in starts[sid])
        for sid, r0, r1, b0, b1 in cells])
    # the rotation under way at t0 + 0.1 s is the one starting at t0
    for sid, t0s in starts.items():
        assert np.allclose(rotation_middle(radar[sid], t0s + 0.1), t0s + radar[sid].period / 2)
    assert expected.min() > 50  # every cell holds clutter
    lo, hi = poisson.interval(0.9999, expected)
    assert np.all((observed >= lo) & (observed <= hi)), (observed, expected)


def test_weather_cells_start_where_the_layout_puts_them_and_drift_with_the_wind():
    base = preset("radars-clutter", scans=SCANS)
    scene = clutter_scene("weather", base)
    reg, ta, tb = base.region, base.first * base.T, base.last * base.T
    w, h = reg.xmax - reg.xmin, reg.ymax - reg.ymin
    cells = [p.component for p in scene.parts]
    assert len(cells) == 3
    for c, (fx, fy) in zip(cells, ((0.30, 0.60), (0.50, 0.35), (0.70, 0.65)), strict=True):
        assert c.centre(ta) == pytest.approx((reg.xmin + fx * w, reg.ymin + fy * h))
        assert c.centre(tb) == pytest.approx((reg.xmin + fx * w + WIND[0] * (tb - ta),
                                              reg.ymin + fy * h + WIND[1] * (tb - ta)))
        s0 = 0.03 * min(w, h)
        assert c.sigma == pytest.approx(s0)
        assert c.sigma_at(c.t_on + (tb - ta)) == pytest.approx(2 * s0)


def test_every_scene_fits_any_radars_and_a_crossing_scenario_is_refused():
    base = preset("radars-clutter", scans=SCANS)
    moved = dataclasses.replace(base, sensors=tuple(
        dataclasses.replace(s, position=(s.position[0] + 5000.0 * s.id, -3000.0),
                            max_range=30_000.0 + 10_000.0 * s.id) for s in base.sensors))
    for name in SCENES:
        sc = with_clutter_scene(moved, name)
        assert sc.name == f"radars-clutter+{name}"
        assert len(simulate(sc, seed=1).plots) > len(simulate(moved, seed=1).plots)
    with pytest.raises(ValueError, match="rotating radars"):
        with_clutter_scene(preset("crossing"), "storm")
    with pytest.raises(ValueError, match="unknown clutter scene 'fog'"):
        clutter_scene("fog", base)


def test_same_seed_same_plots_and_the_scene_leaves_the_other_draws_alone():
    sc = _storm()
    a, b = simulate(sc, seed=5).plots, simulate(sc, seed=5).plots
    for col in ("time", "x", "y", "range", "bearing", "origin", "sensor"):
        assert np.array_equal(getattr(a, col), getattr(b, col))
    assert not np.array_equal(simulate(sc, seed=6).plots.x[:50], a.x[:50])
    # the targets' plots and each radar's own clutter come from their own streams
    base = simulate(dataclasses.replace(sc, clutter_scene=None), seed=5).plots
    key = {(round(float(t), 9), int(s)) for t, s in zip(a.time, a.sensor, strict=True)}
    assert all((round(float(t), 9), int(s)) in key
               for t, s in zip(base.time, base.sensor, strict=True))


def test_the_scene_round_trips_through_the_toml_form_and_errors_name_the_key():
    sc = _storm()
    d = sc.to_dict()
    assert Scenario.from_dict(d) == sc
    assert "clutter_scene" not in preset("radars-clutter").to_dict()
    bad = {**d, "clutter_scene": {"name": "x", "parts": [
        {**d["clutter_scene"]["parts"][0], "scale": -1.0}]}}
    with pytest.raises(ValueError, match=r"^clutter_scene\.parts\[0\]\.scale: must be > 0"):
        Scenario.from_dict(bad)
    bad["clutter_scene"]["parts"][0] = {"kind": "fog"}
    with pytest.raises(ValueError, match=r"clutter_scene\.parts\[0\]\.kind: expected one of"):
        Scenario.from_dict(bad)


def test_simulate_writes_the_scene_into_scenario_toml(tmp_path):
    from click.testing import CliRunner

    from mhtrack.cli.data_commands import simulate as simulate_cmd
    from mhtrack.scenario import load_scenario

    out = tmp_path / "sim"
    res = CliRunner().invoke(simulate_cmd, ["radars-clutter", "--scans", "12", "--seed", "2",
                                            "--clutter-scene", "burst", "--out", str(out)])
    assert res.exit_code == 0, res.output
    sc = load_scenario(out / "scenario.toml")
    assert sc == with_clutter_scene(preset("radars-clutter", scans=12), "burst")
    bad = CliRunner().invoke(simulate_cmd, ["crossing", "--clutter-scene", "burst", "--out",
                                            str(tmp_path / "x")])
    assert bad.exit_code != 0 and "--clutter-scene" in bad.output
