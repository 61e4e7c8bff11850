"""Slant ↔ ground range against the straight line between ECEF points on the WGS-84
ellipsoid (pyproj), and closed-form cases."""

from __future__ import annotations

import numpy as np
import pyproj
import pytest

from mhtrack.io.asterix.earth import WGS84_A, ground_range, radius, slant_range
from mhtrack.models.geodesy import direct

#: Largest error accepted against the geometric reference (m): a tenth of one LSB of
#: I048/040 RHO (1/256 NM = 7.2 m) would be 0.7 m; the model does better than 0.5 m.
TOLERANCE_M = 0.5


@pytest.mark.parametrize("site", [(51.4775, -0.4614, 30.0), (0.0, 10.0, 0.0),
                                  (69.3, 16.1, 1200.0), (-33.9, 151.2, 80.0)])
def test_against_ecef_straight_line(site: tuple[float, float, float]) -> None:
    lat0, lon0, h0 = site
    rng = np.random.default_rng(7)
    n = 3000
    s = rng.uniform(500.0, 3.0e5, n)  # geodesic ground distance, m
    az = rng.uniform(0.0, 360.0, n)
    ht = rng.uniform(0.0, 45000 * 0.3048, n)  # up to FL 450
    lat, lon = direct(lat0, lon0, az, s)  # the target's foot point, exactly s away
    ecef = pyproj.Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)
    x, y, z = ecef.transform(lon, lat, ht)
    x0, y0, z0 = ecef.transform(lon0, lat0, h0)
    rho = np.sqrt((x - x0) ** 2 + (y - y0) ** 2 + (z - z0) ** 2)
    assert np.abs(ground_range(rho, az, ht, lat0, h0) - s).max() < TOLERANCE_M
    assert np.abs(slant_range(s, az, ht, lat0, h0) - rho).max() < TOLERANCE_M


def test_closed_forms() -> None:
    # straight up: no ground range
    assert ground_range(np.array([3000.0]), 0.0, np.array([3100.0]), 45.0, 100.0)[0] == 0.0
    # same height: chord 2R sin(s/2R) of the arc s
    r = float(radius(45.0, 30.0))
    s = 2.0e5
    chord = 2 * r * np.sin(s / (2 * r))
    assert ground_range(np.array([chord]), 30.0, np.array([0.0]), 45.0, 0.0)[0] == \
        pytest.approx(s, abs=1e-6)
    # Euler radius: M (north-south) at the equator is a(1−e²), N (east-west) is a
    assert float(radius(0.0, 90.0)) == pytest.approx(WGS84_A)
    assert float(radius(0.0, 0.0)) == pytest.approx(6335439.327, abs=1e-3)


def test_inverse_pair() -> None:
    rng = np.random.default_rng(3)
    s = rng.uniform(0.0, 4.5e5, 1000)
    az = rng.uniform(0.0, 360.0, 1000)
    h = rng.uniform(0.0, 15000.0, 1000)
    back = ground_range(slant_range(s, az, h, 52.0, 50.0), az, h, 52.0, 50.0)
    assert np.abs(back - s).max() < 1e-6
