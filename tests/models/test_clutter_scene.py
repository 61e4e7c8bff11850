"""Clutter-scene components: each sampler against its own intensity's closed-form mass over
polar and box cells (Poisson intervals over many seeded rotations), the drift in closed
form, and the validation of the fields."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import norm, poisson

from mhtrack.models.clutter_scene import (
    Burst,
    ClutterScene,
    GroundClutter,
    ScenePart,
    SeaBand,
    WeatherCell,
    polar_about,
)

SITE = (1000.0, -2000.0)
ROTATIONS = 400


def _counts(comp, t: float, cells, seed: int = 7) -> np.ndarray:
    """Plots per cell summed over ROTATIONS rotations (Poisson(rate) draws each)."""
    scene = ClutterScene("one", (ScenePart(comp),))
    rng = np.random.default_rng(seed)
    out = np.zeros(len(cells))
    for _ in range(ROTATIONS):
        xy = scene.sample(rng, 1, t, SITE)
        r, th = polar_about(xy, SITE)
        for i, cell in enumerate(cells):
            out[i] += np.count_nonzero(cell(r, np.degrees(th), xy))
    return out


def _within_poisson(observed: np.ndarray, expected: np.ndarray) -> None:
    lo, hi = poisson.interval(0.9999, expected)
    assert np.all((observed >= lo) & (observed <= hi)), (observed, expected)


def _polar_cell(r0: float, r1: float, b0: float, b1: float):
    return lambda r, b, xy: (r >= r0) & (r < r1) & (b >= b0) & (b < b1)


def _quadrature(comp, t: float, r0: float, r1: float, b0: float, b1: float,
                n: int = 400) -> float:
    """∫ N f dA over a polar cell by the midpoint rule in (r, θ) (dA = r dr dθ)."""
    r = r0 + (r1 - r0) * (np.arange(n) + 0.5) / n
    th = np.radians(b0 + (b1 - b0) * (np.arange(n) + 0.5) / n)
    R, TH = np.meshgrid(r, th)
    xy = np.column_stack((SITE[0] + (R * np.sin(TH)).ravel(), SITE[1] + (R * np.cos(TH)).ravel()))
    dA = (r1 - r0) / n * math.radians(b1 - b0) / n
    return float(comp.rate(t) * (comp.density(xy, t, SITE) * R.ravel()).sum() * dA)


def test_ground_clutter_counts_match_the_closed_form_mass_per_polar_cell():
    g = GroundClutter(30.0, 3000.0, ripple=0.7, lobes=3, phase_deg=20.0)
    cells = [(0, 2000, 0, 60), (2000, 5000, 60, 200), (1000, 8000, 200, 360)]

    def mass(r0, r1, b0, b1):  # N (e^{-r0²/2L²} − e^{-r1²/2L²}) · angular share
        radial = math.exp(-r0**2 / 2 / 3000**2) - math.exp(-r1**2 / 2 / 3000**2)
        t0, t1, p = math.radians(b0), math.radians(b1), math.radians(20.0)
        ang = (t1 - t0 + 0.7 / 3 * (math.sin(3 * (t1 - p)) - math.sin(3 * (t0 - p))))
        return 30.0 * radial * ang / (2 * math.pi)

    expected = np.array([mass(*c) for c in cells])
    assert np.allclose(expected, [_quadrature(g, 0.0, *c) for c in cells], rtol=1e-4)
    _within_poisson(_counts(g, 0.0, [_polar_cell(*c) for c in cells]), ROTATIONS * expected)


def test_weather_cell_counts_match_its_gaussian_box_mass_and_sin2_life():
    w = WeatherCell(-5000.0, 2000.0, 20.0, -10.0, 1500.0, 4.0, 25.0, 100.0, 500.0)
    t = 250.0
    cx, cy = w.centre(t)
    s = w.sigma_at(t)
    assert (cx, cy) == (-5000.0 + 20.0 * t, 2000.0 - 10.0 * t)
    assert s == 1500.0 + 4.0 * (t - 100.0)
    assert w.rate(t) == pytest.approx(25.0 * math.sin(math.pi * 150 / 400) ** 2)
    assert w.rate(99.0) == w.rate(501.0) == 0.0
    boxes = [(cx - s, cx + s, cy - s, cy + s), (cx + s, cx + 3 * s, cy - 2 * s, cy)]

    def cell(b):
        return lambda r, th, xy: ((xy[:, 0] >= b[0]) & (xy[:, 0] < b[1])
                                  & (xy[:, 1] >= b[2]) & (xy[:, 1] < b[3]))

    def mass(b):
        return w.rate(t) * ((norm.cdf(b[1], cx, s) - norm.cdf(b[0], cx, s))
                            * (norm.cdf(b[3], cy, s) - norm.cdf(b[2], cy, s)))

    _within_poisson(_counts(w, t, [cell(b) for b in boxes]),
                    ROTATIONS * np.array([mass(b) for b in boxes]))


def test_drift_moves_the_sampled_centre_by_v_t():
    w = WeatherCell(0.0, 0.0, 15.0, 7.0, 800.0, 0.0, 50.0, -1000.0, 1000.0)
    rng = np.random.default_rng(3)
    for t in (0.0, 120.0, 480.0):
        xy = w.sample(rng, 20000, t, SITE)
        se = 800.0 / math.sqrt(20000)
        assert np.allclose(xy.mean(axis=0), (15.0 * t, 7.0 * t), atol=5 * se)


def test_sea_band_and_burst_counts_match_their_polar_mass():
    sea = SeaBand(5.0, 25.0, 0.0, 100.0, 20000.0, 2000.0, 330.0, 60.0)  # across north
    assert sea.rate(50.0) == 15.0 and sea.rate(-5.0) == 5.0 and sea.rate(500.0) == 25.0
    cells = [(18000, 22000, 330, 360), (15000, 30000, 0, 30), (0, 50000, 90, 300)]

    def sea_mass(r0, r1, b0, b1):  # N (Φ(r1) − Φ(r0)) · share of the 60° sector
        return 15.0 * (norm.cdf(r1, 20000, 2000) - norm.cdf(r0, 20000, 2000)) * (b1 - b0) / 60
    exp_sea = np.array([sea_mass(*c) for c in cells[:2]] + [0.0])
    assert np.allclose(exp_sea, [_quadrature(sea, 50.0, *c) for c in cells], atol=1e-3)
    _within_poisson(_counts(sea, 50.0, [_polar_cell(*c) for c in cells]), ROTATIONS * exp_sea)

    burst = Burst(40.0, 10.0, 12.0, 60.0, 20.0, 5000.0, 45000.0)
    assert burst.rate(9.9) == burst.rate(22.0) == 0.0 and burst.rate(21.9) == 40.0
    cells = [(5000, 25000, 60, 70), (25000, 45000, 60, 80), (0, 50000, 80, 360)]
    exp_b = np.array([40.0 * 0.5 * 0.5, 40.0 * 0.5, 0.0])
    assert np.allclose(exp_b, [_quadrature(burst, 15.0, *c) for c in cells], atol=1e-3)
    _within_poisson(_counts(burst, 15.0, [_polar_cell(*c) for c in cells]), ROTATIONS * exp_b)


def test_scene_sums_only_the_parts_a_radar_sees():
    g = GroundClutter(10.0, 1000.0)
    b = Burst(40.0, 0.0, 10.0, 0.0, 10.0, 1000.0, 2000.0)
    scene = ClutterScene("s", (ScenePart(g), ScenePart(b, (2,))))
    assert scene.rate(1, 5.0) == 10.0 and scene.rate(2, 5.0) == 50.0
    xy = np.array([[SITE[0] + 100.0, SITE[1] + 1500.0]])
    assert scene.intensity(1, xy, 5.0, SITE) == pytest.approx(10.0 * g.density(xy, 5.0, SITE))
    assert scene.intensity(2, xy, 5.0, SITE) == pytest.approx(
        10.0 * g.density(xy, 5.0, SITE) + 40.0 * b.density(xy, 5.0, SITE))


@pytest.mark.parametrize("make, match", [
    (lambda: WeatherCell(0, 0, 0, 0, 0.0, 0, 1, 0, 1), "sigma: must be > 0"),
    (lambda: WeatherCell(0, 0, 0, 0, 1.0, -1.0, 1, 0, 1), "growth: must be >= 0"),
    (lambda: WeatherCell(0, 0, 0, 0, 1.0, 0, 1, 5, 5), "t_off: must be > t_on"),
    (lambda: GroundClutter(1.0, 10.0, ripple=1.0), r"ripple: must be in \[0, 1\)"),
    (lambda: GroundClutter(1.0, 10.0, lobes=0), "lobes: must be an integer >= 1"),
    (lambda: SeaBand(1, 1, 0, 1, 1000, 10, 0, 400), "width_deg: must be <= 360"),
    (lambda: Burst(1, 0, 1, 0, 10, 2000, 1000), "range_max: must be > range_min"),
    (lambda: Burst(float("nan"), 0, 1, 0, 10, 1000, 2000), "rate_per_rotation: must be finite"),
])
def test_bad_fields_are_named(make, match):
    with pytest.raises(ValueError, match=match):
        make()
