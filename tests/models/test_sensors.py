"""Sensor models: polar geometry by hand, UCM consistency by Monte-Carlo."""

import numpy as np
import pytest

from mhtrack.models.sensors import CartesianSensor, PolarRadar


def test_polar_geometry_hand_worked():
    r = PolarRadar(1, position=(100.0, 200.0))
    rb = r.to_polar(np.array([[100.0, 1200.0], [1100.0, 200.0], [100.0, -800.0]]))
    # north, east, south of the radar at 1 km: bearings 0, 90, 180 deg clockwise from north
    assert np.allclose(rb, [[1000, 0], [1000, 90], [1000, 180]])


@pytest.mark.parametrize("bearing_sigma", [0.3, 5.0])
def test_unbiased_converted_measurement_is_consistent(bearing_sigma):
    """Mean error ~ 0 and NEES ~ 2 (chi-square, 2 dof) — the defining UCM properties."""
    radar = PolarRadar(0, (1000.0, -500.0), sigma_range=20.0, sigma_bearing_deg=bearing_sigma)
    rng = np.random.default_rng(0)
    truth = np.array([[3000.0, 4000.0]])
    n = 100_000
    obs = radar.observe(rng, np.repeat(truth, n, axis=0))
    err = obs.z - truth
    sd = np.sqrt(np.diag(obs.R.mean(0)))
    assert np.all(np.abs(err.mean(0)) < 5 * sd / np.sqrt(n))
    nees = np.einsum("ni,nij,nj->n", err, np.linalg.inv(obs.R), err)
    assert nees.mean() == pytest.approx(2.0, rel=0.03)


def test_polar_place_round_trip():
    radar = PolarRadar(0, (10.0, 20.0))
    z = np.array([[500.0, 700.0], [-3000.0, 2.0]])
    back = radar.place(z).z
    lam = np.exp(-np.radians(0.3) ** 2 / 2)
    assert np.allclose((back - radar.position) * lam, z - radar.position)


def test_cartesian_sensor_validates():
    with pytest.raises(ValueError, match="sigma"):
        CartesianSensor(0, sigma=0.0)
