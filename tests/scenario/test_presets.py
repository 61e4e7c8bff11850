"""Presets against P1 §3 / P2 §3 (``docs/scenarios.md``), and their overrides."""

from pathlib import Path

import numpy as np
import pytest

from mhtrack.models.clutter import GaussianMixtureClutter, UniformClutter
from mhtrack.models.sensors import CartesianSensor, PolarRadar
from mhtrack.scenario import (
    PRESETS,
    apply_overrides,
    default_mixture,
    load_scenario,
    preset,
    simulate_truth,
)
from mhtrack.scenario.presets import multiradar_headings

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "examples" / "drifting-clutter.toml"


def test_names():
    assert PRESETS == ("crossing", "crossing-wide", "multiradar", "opensky", "opensky-radars",
                       "crossing-changing", "radars-clutter")
    with pytest.raises(ValueError, match=r"unknown preset 'cross' \(expected crossing, "):
        preset("cross")


def test_crossing_parameters():
    s = preset("crossing")
    assert s.region.as_tuple() == (-4000, 4000, -4000, 4000)
    assert (s.T, s.scans, s.pd, s.truth_sigma_v) == (1.0, (1, 90), (0.9,), 0.0)
    (sensor,) = s.sensors
    assert isinstance(sensor, CartesianSensor) and np.allclose(sensor.R, 1e4 * np.eye(2))
    assert [(t.state, t.birth, t.death) for t in s.targets] == [
        ((2000, -70, 3000, -60), 1, 80),
        ((-3000, 80, 2000, -100), 40, 90),
        ((-2000, 80, 3000, -100), 30, 90),
        ((3000, -70, 2000, -60), 1, 80),
    ]
    c = s.clutter
    assert isinstance(c, GaussianMixtureClutter) and c.rate_per_scan == 40
    assert np.allclose(c.weights, 0.25)
    assert c.means.tolist() == [[-2000, 1000], [700, 700], [400, 600], [500, 600]]
    assert np.allclose(c.covariances[:, [0, 1], [0, 1]], [[800, 800]] + [[1000, 1000]] * 3)
    assert np.all(c.covariances[:, 0, 1] == 0)
    w = preset("crossing-wide").clutter
    assert np.allclose(
        w.covariances[:, [0, 1], [0, 1]], [[800**2, 800**2]] + [[1000**2, 1000**2]] * 3
    )
    assert preset("crossing-wide").targets == s.targets


def test_multiradar_parameters():
    s = preset("multiradar")
    assert (s.T, s.scans, s.pd) == (1.0, (1, 10), (1.0, 1.0, 1.0))
    assert s.region.area == pytest.approx(2e8)
    assert s.region.xmax - s.region.xmin == pytest.approx(s.region.ymax - s.region.ymin)
    centre = np.array([(s.region.xmin + s.region.xmax) / 2, (s.region.ymin + s.region.ymax) / 2])
    assert np.allclose(centre, [1750, 2650])  # centre of the initial positions' box
    x0 = np.array([t.state for t in s.targets])
    assert np.allclose(
        x0[:, [0, 2]] / 1000,
        [
            (2.5, 2.3),
            (2.5, 2.5),
            (3.0, 3.0),
            (3.0, 2.0),
            (1.0, 1.5),
            (1.5, 4.0),
            (1.3, 3.8),
            (1.0, 1.3),
            (0.5, 2.7),
            (0.5, 3.0),
        ],
    )
    assert np.allclose(np.hypot(x0[:, 1], x0[:, 3]), 200.0)
    assert len({round(h) for h in multiradar_headings()}) == 10  # all different headings
    assert all(t.birth == 1 and t.death == 10 for t in s.targets)
    assert len(s.sensors) == 3 and all(isinstance(r, PolarRadar) for r in s.sensors)
    for r in s.sensors:
        assert (r.sigma_range, r.sigma_bearing_deg) == (20.0, 0.3)
        assert np.hypot(*(np.asarray(r.position) - centre)) == pytest.approx(10_000)
    assert isinstance(s.clutter, UniformClutter) and s.clutter.rate_per_scan == 50
    # headings come from a seed fixed in the preset, not from the simulation seed
    assert preset("multiradar") == s
    assert preset("multiradar", heading_seed=1) != s
    truth = simulate_truth(s)
    assert s.region.contains(truth.positions).all()


def test_opensky_parameters():
    s = preset("opensky")
    assert (s.T, s.scans, s.pd) == (10.0, (0, 120), (0.9, 0.9))
    assert [(r.sigma_range, r.sigma_bearing_deg) for r in s.sensors] == [(50, 0.15)] * 2
    assert s.region.contains(np.array([r.position for r in s.sensors])).all()
    assert isinstance(s.clutter, GaussianMixtureClutter) and s.clutter.rate_per_scan == 20
    assert s.clutter.background == 0.2
    truth = simulate_truth(s)
    assert s.region.contains(truth.positions).all()
    short = preset("opensky", scans=3)
    assert short.scans == (0, 2)
    assert all(t.death <= 2 for t in short.targets)
    assert len(short.targets) == 50  # aircraft with a row in scans 0–2


def test_overrides():
    s = preset(
        "crossing", clutter="uniform", clutter_rate=12.5, pd=0.7, scans=20, truth_sigma_v=3.0
    )
    assert isinstance(s.clutter, UniformClutter) and s.clutter.rate_per_scan == 12.5
    assert s.clutter.region == s.region
    assert (s.pd, s.scans, s.truth_sigma_v) == ((0.7,), (1, 20), 3.0)
    assert preset("crossing", clutter="gmm") == preset("crossing")
    assert preset("crossing", clutter=None, pd=None) == preset("crossing")  # None ignored
    m = preset("multiradar", clutter="gmm")
    assert m.clutter.rate_per_scan == 50
    ref = default_mixture(m.region, 50.0)
    assert np.allclose(m.clutter.means, ref.means)
    # default mixture: centre ± (w/4, h/4), σ = w/10
    w = m.region.xmax - m.region.xmin
    assert np.allclose(np.abs(ref.means - [1750, 2650]), w / 4)
    assert np.allclose(ref.covariances[0], np.eye(2) * (w / 10) ** 2)
    r = preset("multiradar", sigma_range=60.0)
    assert all(x.sigma_range == 60.0 for x in r.sensors)
    o = preset("opensky", clutter_rate=5.0, pd=1.0)
    assert o.clutter.rate_per_scan == 5.0 and o.pd == (1.0, 1.0)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"pd": 1.5}, r"^pd: must be in \(0, 1\]"),
        ({"pd": "high"}, r"^pd: expected a number"),
        ({"scans": 0}, r"^scans: must be >= 1"),
        ({"scans": 2.5}, r"^scans: expected an integer"),
        ({"clutter": "foo"}, r"^clutter: unknown 'foo' \(expected uniform, gmm\)"),
        ({"clutter_rate": -1}, r"^clutter_rate: must be >= 0"),
        ({"clutter_rate": float("nan")}, r"^clutter_rate: must be finite"),
        ({"sigma_range": 30.0}, r"^sigma_range: scenario 'crossing' has no polar sensor"),
        ({"heading_seed": 3}, r"^heading_seed: only the multiradar preset"),
        ({"lambda_": 3}, r"^unknown override 'lambda_'"),
    ],
)
def test_bad_overrides(kw, message):
    with pytest.raises(ValueError, match=message):
        preset("crossing", **kw)


def test_apply_overrides_on_a_custom_scenario():
    s = load_scenario(EXAMPLE)
    o = apply_overrides(s, clutter="uniform", pd=0.5, scans=10, clutter_rate=None)
    assert isinstance(o.clutter, UniformClutter)
    assert o.clutter.rate_per_scan == s.clutter.rate(1) == 10.0  # rate of the first scan
    assert (o.pd, o.scans, o.targets) == ((0.5, 0.5), (1, 10), s.targets)
    g = apply_overrides(s, clutter="gmm", clutter_rate=3.0)  # keeps the time-varying mixture
    assert [m.rate_per_scan for _, m in g.clutter.keyframes] == [3.0, 3.0]
    assert np.array_equal(g.clutter.at(30).means, s.clutter.at(30).means)
    assert apply_overrides(s) == s
    r = apply_overrides(s, sigma_range=40.0)
    assert [getattr(x, "sigma_range", None) for x in r.sensors] == [None, 40.0]
    with pytest.raises(ValueError, match=r"^unknown override 'heading_seed'"):
        apply_overrides(s, heading_seed=1)
    with pytest.raises(ValueError, match=r"^scans: must be >= 1"):
        apply_overrides(s, scans=-2)
