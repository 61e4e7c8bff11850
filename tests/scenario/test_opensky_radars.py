"""The ``opensky-radars`` preset: sites, parameters, coverage and the simulated plots.

Distances and coverage are measured with GeographicLib (independent of pyproj); the
figures asserted here are the ones docs/scenarios.md gives."""

import itertools

import numpy as np
import pytest
from geodesic_reference import WGS84

from mhtrack.models.sensors import RotatingRadar
from mhtrack.scenario import preset, simulate


@pytest.fixture(scope="module")
def sim():
    return simulate(preset("opensky-radars"), seed=1)


def _dist(lat1, lon1, lat2, lon2):
    return WGS84.Inverse(lat1, lon1, lat2, lon2)["s12"]


def test_three_rotating_radars_with_different_parameters():
    sc = preset("opensky-radars")
    radars = sc.sensors
    assert len(radars) == 3 and all(isinstance(r, RotatingRadar) for r in radars)
    assert sorted(r.period for r in radars) == [4.0, 10.0, 12.0]
    assert len({r.sigma_range for r in radars}) == 3
    assert all(30 <= r.sigma_range <= 80 and 0.08 <= r.sigma_bearing_deg <= 0.2
               for r in radars)
    assert all(0.85 <= p <= 0.95 for p in sc.pd) and len(set(sc.pd)) == 3
    assert all(r.clutter_rate > 0 and len(r.clutter_patches) == 1 for r in radars)
    for a, b in itertools.combinations(radars, 2):
        assert 100e3 <= _dist(a.lat, a.lon, b.lat, b.lon) <= 200e3
    assert sc.origin == (52.067, -1.454)
    assert (sc.first * sc.T, sc.last * sc.T) == (0.0, 1200.0)


def test_coverage_two_radars_for_most_of_every_track(sim):
    sc, tr = sim.scenario, sim.truth
    lat, lon = sc.sensor_set().frame().to_geodetic(tr.x, tr.y)
    lat, lon = lat[::5], lon[::5]  # every 5 s
    tid = tr.target_id[::5]
    n = sum(np.array([_dist(r.lat, r.lon, a, b) for a, b in zip(lat, lon, strict=True)])
            <= r.max_range for r in sc.sensors)
    assert (n >= 1).all()
    assert (n >= 2).mean() >= 0.96
    ids = np.unique(tr.target_id)
    assert ids.size == 84
    mostly = sum((n[tid == i] >= 2).mean() > 0.5 for i in np.unique(tid))
    assert mostly >= 78


def test_plots_and_truth_counts(sim):
    p, tr = sim.plots, sim.truth
    assert p.timed and p.origin is not None and p.R is not None
    assert np.unique(p.origin[p.origin >= 0]).size >= 83
    counts = {s: int((p.sensor == s).sum()) for s in (1, 2, 3)}
    clutter = {s: int(((p.sensor == s) & (p.origin < 0)).sum()) for s in (1, 2, 3)}
    # uniform 20 per rotation + a patch of 8 / 6 / 8 (few dropped beyond max_range)
    for s, (period, patch) in {1: (4.0, 8.0), 2: (10.0, 6.0), 3: (12.0, 8.0)}.items():
        mean = 1200 / period * (20.0 + patch)
        assert abs(clutter[s] - mean) < 5 * np.sqrt(mean)
    assert counts[1] > counts[2] > counts[3]
    np.testing.assert_array_equal(np.unique(tr.time), np.arange(1201.0))


def test_same_seed_same_plots(sim):
    again = simulate(preset("opensky-radars"), seed=1).plots
    for name in ("time", "sensor", "range", "bearing", "origin", "x", "y"):
        np.testing.assert_array_equal(getattr(again, name), getattr(sim.plots, name))
