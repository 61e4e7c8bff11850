"""Clutter-accuracy formulas: the IAE quadrature against closed forms, the quadrature check
and the uniform guess by hand."""

from typing import Any

import numpy as np
import pytest
from scipy.special import erf

from mhtrack.metrics.clutter import (
    DEFAULT_RESOLUTION,
    integrated_absolute_error,
    quadrature_relative_error,
    true_intensity_grid,
    uniform_guess,
)
from mhtrack.models.clutter import Region
from mhtrack.scenario import preset, simulate

REGION = Region(-4000.0, 4000.0, -4000.0, 4000.0)


def _iae(f: Any, g: Any, n: int = DEFAULT_RESOLUTION) -> float:
    z, cell = REGION.grid(n)
    return integrated_absolute_error(f(z), g(z), cell)


def _box(z: np.ndarray, x0: float, x1: float, y0: float, y1: float) -> np.ndarray:
    return ((z[:, 0] >= x0) & (z[:, 0] <= x1) & (z[:, 1] >= y0) & (z[:, 1] <= y1)).astype(float)


def test_two_uniform_intensities_closed_form() -> None:
    a, b = 40.0 / REGION.area, 1e-5
    # b on a 2 km × 1 km box, a everywhere: ∫|κ̂−κ| = |b−a|·2e6 + a·(A − 2e6)
    box = (-1000.0, 1000.0, 0.0, 1000.0)  # edges on cell boundaries (20 m cells)
    exact = abs(b - a) * 2e6 + a * (REGION.area - 2e6)
    got = _iae(lambda z: np.full(len(z), a), lambda z: b * _box(z, *box))
    assert got == pytest.approx(exact, rel=1e-12)
    # edges inside cells: error at most the cells the edges cross, O(h·perimeter)
    box = (-1013.0, 1007.0, 3.0, 1011.0)
    area = 2020.0 * 1008.0
    exact = abs(b - a) * area + a * (REGION.area - area)
    got = _iae(lambda z: np.full(len(z), a), lambda z: b * _box(z, *box))
    h = 8000.0 / DEFAULT_RESOLUTION
    assert abs(got - exact) <= abs(b - a) * h * 2 * (2020.0 + 1008.0)
    assert got == pytest.approx(exact, rel=0.02)


@pytest.mark.parametrize("sigma", [28.0, 100.0, 1000.0])
def test_gaussian_mass_at_the_default_resolution(sigma: float) -> None:
    """The narrowest crossing clump (σ ≈ 28 m) is integrated to 1e−4 on 20 m cells."""
    lam, mu = 10.0, np.array([733.0, -411.0])  # off the cell centres on purpose

    def kappa(z: np.ndarray) -> np.ndarray:
        d2 = ((z - mu) ** 2).sum(axis=1)
        return lam * np.exp(-0.5 * d2 / sigma**2) / (2 * np.pi * sigma**2)

    def axis_mass(m: float) -> float:
        return 0.5 * (erf((4000 - m) / (sigma * 2**0.5)) - erf((-4000 - m) / (sigma * 2**0.5)))

    exact = lam * axis_mass(mu[0]) * axis_mass(mu[1])
    assert _iae(kappa, lambda z: np.zeros(len(z))) == pytest.approx(exact, rel=1e-4)


def test_iae_input_checks() -> None:
    with pytest.raises(ValueError, match="differ"):
        integrated_absolute_error(np.zeros(3), np.zeros(4), 1.0)


def test_quadrature_relative_error_by_hand() -> None:
    # 4 cells of 2 m² holding 1, 2, 3, 4 plots/m²: mass 20 against a true 16 -> 0.25
    assert quadrature_relative_error(np.array([1.0, 2.0, 3.0, 4.0]), 2.0, 16.0) == 0.25
    assert quadrature_relative_error(np.zeros(4), 2.0, 0.0) == 0.0


def test_uniform_clutter_truth_and_guess() -> None:
    # 25 uniform plots per scan over the 8 km square: κ = 25 / 6.4e7 everywhere
    sim = simulate(preset("crossing", scans=2, clutter="uniform", clutter_rate=25.0), seed=3)
    assert uniform_guess(sim) == pytest.approx(25.0 / REGION.area)
    z, _ = REGION.grid(10)
    np.testing.assert_allclose(true_intensity_grid(sim, 1, z), 25.0 / REGION.area)
