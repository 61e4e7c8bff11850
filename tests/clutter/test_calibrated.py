"""The map-calibrated mixture: its ratio against counts done by hand, its correction of a
wrong base toward the truth, its state, and its assembly per radar."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.build import make_tracker
from mhtrack.clutter.calibrated import MapCalibratedClutter
from mhtrack.clutter.gmm import GMMClutter
from mhtrack.clutter.known import KnownClutter
from mhtrack.clutter.per_sensor import PerSensorClutter
from mhtrack.clutter.polar import PolarClutter
from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.records import Scan

R = 10_000.0


def _scan(k: int, z: np.ndarray, dt: float = 4.0) -> Scan:
    z = np.asarray(z, float).reshape(-1, 2)
    return Scan(k, k * dt, z, np.zeros(len(z), np.int64), np.arange(len(z)))


def _disc(rng: np.random.Generator, n: int) -> np.ndarray:
    r = R * np.sqrt(rng.random(n))
    t = 2 * np.pi * rng.random(n)
    return np.column_stack([r * np.sin(t), r * np.cos(t)])


def _est(kappa: float, **kw: object) -> MapCalibratedClutter:
    return MapCalibratedClutter(base=KnownClutter(kappa), range_cell=2500.0, n_azimuth=8,
                                max_range=R, **kw)  # type: ignore[arg-type]


def test_ratio_is_observed_over_expected_counts_by_hand() -> None:
    """Without smoothing and with a constant base ``κ₀``: ``E_c = Σ_k γ^(K−k) κ₀ A_c`` and
    ``S_c`` the discounted plots counted per cell by hand (ring ``⌊r/Δr⌋``, sector
    ``⌊θ/Δθ⌋``), ``γ = 2^(−4/h)``; ``κ̂ = κ₀ (S_c + b₀)/(E_c + b₀)``."""
    rng = np.random.default_rng(4)
    k0, h, b0 = 3e-7, 20.0, 5.0
    est = _est(k0, smoothing=0, half_life=h, prior_count=b0)
    g = 2.0 ** (-4.0 / h)
    s = np.zeros((4, 8))
    looks = 0.0
    for k in range(6):
        z = _disc(rng, 60)
        est.update(_scan(k, z))
        ring = np.floor(np.hypot(z[:, 0], z[:, 1]) / 2500.0).astype(int)
        sector = (np.mod(np.arctan2(z[:, 0], z[:, 1]), 2 * np.pi) / (np.pi / 4)).astype(int)
        s = (g if k else 1.0) * s
        np.add.at(s, (ring, sector), 1.0)
        looks = (g if k else 1.0) * looks + 1.0
    area = 0.5 * (np.pi / 4) * (2 * np.arange(4) + 1)[:, None] * 2500.0**2
    e = looks * k0 * np.repeat(area, 8, axis=1)
    np.testing.assert_allclose(est.counts.sums_, s, rtol=1e-12)
    np.testing.assert_allclose(est.expected_, e, rtol=1e-12)
    q = _disc(rng, 40)
    ring = np.floor(np.hypot(q[:, 0], q[:, 1]) / 2500.0).astype(int)
    sector = (np.mod(np.arctan2(q[:, 0], q[:, 1]), 2 * np.pi) / (np.pi / 4)).astype(int)
    expect = k0 * (s[ring, sector] + b0) / (e[ring, sector] + b0)
    np.testing.assert_allclose(est.intensity(q), expect, rtol=1e-12)
    far = np.array([[0.0, 3 * R]])
    assert est.intensity(far)[0] == k0  # beyond the map: the base


def test_a_base_wrong_by_half_is_corrected_toward_the_truth() -> None:
    """Uniform clutter of ``κ = n/(πR²)``; a base at ``κ/2``: after 60 rotations with no
    forgetting every cell's calibrated ``κ̂`` is within 4 Poisson σ of ``κ`` (the base is
    2σ off or worse in every cell)."""
    rng = np.random.default_rng(11)
    n = 200
    kappa = n / (np.pi * R**2)
    est = _est(0.5 * kappa, smoothing=0, half_life=np.inf)
    for k in range(60):
        est.update(_scan(k, _disc(rng, n)))
    got = est.ratio() * 0.5 * kappa  # κ̂ in each cell
    expected_count = 60 * kappa * est.counts.areas()  # plots a cell holds over 60 looks
    sigma = kappa / np.sqrt(expected_count)
    assert (np.abs(got - kappa) < 4 * sigma).all()
    assert (0.5 * kappa < kappa - 2 * sigma).all()


def test_state_round_trip_and_hostile_expected_counts() -> None:
    rng = np.random.default_rng(2)
    a = MapCalibratedClutter(range_cell=2500.0, max_range=R)
    b = MapCalibratedClutter(range_cell=2500.0, max_range=R)
    for k in range(5):
        a.update(_scan(k, _disc(rng, 80)))
    b.set_state(a.get_state())
    z = _disc(rng, 80)
    for est in (a, b):
        est.update(_scan(5, z))
        est.forget(np.arange(80) % 5 == 0)
    q = _disc(rng, 50)
    assert np.array_equal(a.intensity(q), b.intensity(q))
    good = a.get_state()
    for bad in (-good["expected"], np.zeros((2, good["expected"].shape[1]))):
        with pytest.raises(ValueError, match="expected"):
            MapCalibratedClutter(range_cell=2500.0, max_range=R).set_state(
                {**good, "expected": bad})
    with pytest.raises(ValueError, match="prior_count"):
        MapCalibratedClutter(prior_count=0.0)


def test_per_radar_about_each_site_with_the_gmm_in_range_and_bearing() -> None:
    sensors = SensorSet(None, (
        RadarSensor(1, "polar", lat=51.0, lon=0.0, sigma_range=50.0, sigma_bearing_deg=0.1,
                    pd=0.9, period=4.0, max_range=60e3),))
    trk = make_tracker("mht-mapgmm", sensors=sensors,
                       clutter_params={"base_params": {"window": 3}})
    assert isinstance(trk.clutter, PerSensorClutter)
    est = trk.clutter.estimator(1)
    assert isinstance(est, MapCalibratedClutter)
    assert est.site == pytest.approx(sensors.site_xy(1))
    assert est.counts.n_rings == 12 and est.range_cell == pytest.approx(5000.0)
    assert isinstance(est.base, PolarClutter) and isinstance(est.base.inner, GMMClutter)
    assert est.base.inner.window == 3
