"""PolarClutter: an estimator run in a radar's own (r, r₀θ), intensities back per m²."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.build import make_tracker
from mhtrack.clutter.gmm import GMMClutter
from mhtrack.clutter.known import KnownClutter
from mhtrack.clutter.polar import PolarClutter
from mhtrack.mht.state import decode, encode
from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.records import Scan


class Seen(KnownClutter):
    """Keeps the positions it was given."""

    def update(self, scan, in_track_gates=None):
        self.z = scan.z.copy()


def test_polar_coordinates_hand_worked():
    # site at (1000, 2000); bearing counted clockwise from grid north, from the cut (south)
    est = PolarClutter(Seen(1.0), (1000.0, 2000.0), r0=1000.0)
    z = np.array([[1000.0, 5000.0],    # 3 km due north: θ = 0° − 180° → 180°
                  [4000.0, 2000.0],    # 3 km due east: 90° − 180° → 270°
                  [1000.0, -1000.0]])  # 3 km due south: at the cut, θ = 0
    est.update(Scan(0, 0.0, z, np.zeros(3, np.int64), np.arange(3)))
    np.testing.assert_allclose(est.inner.z, [[3000.0, 1000.0 * np.pi],
                                             [3000.0, 1500.0 * np.pi],
                                             [3000.0, 0.0]], atol=1e-9)


def test_intensity_is_per_square_metre_of_the_plane():
    # A constant κ_p in (r, r₀θ) holds κ_p·(r₂−r₁)·2π·r₀ plots on the annulus r₁ < r < r₂
    # (closed form). Sum κ(x, y) over a fine Cartesian grid of the plane instead.
    kp, r0, r1, r2 = 2e-7, 5000.0, 2000.0, 9000.0
    est = PolarClutter(KnownClutter(kp), (0.0, 0.0), r0=r0, min_range=1.0)
    h = 20.0
    g = np.arange(-r2, r2, h) + h / 2
    x, y = np.meshgrid(g, g)
    z = np.column_stack([x.ravel(), y.ravel()])
    r = np.hypot(z[:, 0], z[:, 1])
    inside = (r > r1) & (r < r2)
    mass = est.intensity(z[inside]).sum() * h * h
    assert mass == pytest.approx(kp * (r2 - r1) * 2 * np.pi * r0, rel=2e-3)


def test_min_range_keeps_the_site_finite():
    est = PolarClutter(KnownClutter(1e-6), (0.0, 0.0), r0=1000.0, min_range=100.0)
    k = est.intensity(np.array([[0.0, 0.0], [0.0, 50.0], [0.0, 400.0]]))
    np.testing.assert_allclose(k, [1e-5, 1e-5, 2.5e-6])


def test_state_round_trip_continues_identically():
    rng = np.random.default_rng(3)
    est = PolarClutter(GMMClutter(), (0.0, 0.0))
    back = PolarClutter(GMMClutter(), (0.0, 0.0))
    scans = [Scan(k, float(k), rng.uniform(-5e4, 5e4, (40, 2)), np.zeros(40, np.int64),
                  np.arange(40)) for k in range(4)]
    for s in scans[:3]:
        est.update(s)
    arrays: dict = {}
    back.set_state(decode(encode(est.get_state(), arrays), arrays))
    for e in (est, back):
        e.update(scans[3])
    z = rng.uniform(-5e4, 5e4, (20, 2))
    assert est.intensity(z).tolist() == back.intensity(z).tolist()


def test_make_tracker_wraps_each_sited_radar():
    sensors = SensorSet(None, (
        RadarSensor(1, "polar", lat=51.0, lon=0.0, sigma_range=50.0, sigma_bearing_deg=0.1,
                    pd=0.9, period=4.0),
        RadarSensor(2, "polar", lat=51.5, lon=0.5, sigma_range=50.0, sigma_bearing_deg=0.1,
                    pd=0.9, period=6.0)))
    trk = make_tracker("mht-agmm", sensors=sensors)  # polar: the default
    inner = trk.clutter.estimator(2)
    assert isinstance(inner, PolarClutter)
    assert inner.site == pytest.approx(sensors.site_xy(2))
    plane = make_tracker("mht-agmm", sensors=sensors, clutter_frame="plane")
    assert not isinstance(plane.clutter.estimator(2), PolarClutter)
    with pytest.raises(ValueError, match="clutter frame"):
        make_tracker("mht-agmm", sensors=sensors, clutter_frame="spherical")
