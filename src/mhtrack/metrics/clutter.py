"""Accuracy of a clutter-intensity estimator against the simulated truth.

Per scan ``k``:

* **integrated absolute error** ``IAE_k = ∫_R |κ̂_k(z) − κ_k(z)| dz`` over the scenario's
  region ``R`` (plots per scan; 0 is perfect, ``∫κ̂ + ∫κ`` is the worst — disjoint supports).
  Computed by the midpoint rule on the ``n × n`` cell centres of ``Region.grid(n)``,
  default ``n = 400`` (20 m cells on the 8 km ``crossing`` region: the narrowest true
  clutter component there has σ ≈ 28 m, and the midpoint rule on a Gaussian sampled at
  ``h ≲ σ`` is accurate to ~1e−4 of its mass; the kinks of ``|·|`` where the two
  intensities cross converge as ``O(h²)``). The per-scan check ``quadrature_error`` =
  ``|Σκ ΔA − S λ_k| / (S λ_k)`` compares the quadrature of the truth with its exact mass.
* **clutter-count error** ``|M̂_k − S λ_k|`` against the true *mean* count of the scan (the
  Poisson parameter the estimator's ``M̂_k`` estimates; ``S`` sensors each draw ``λ_k``);
  ``count_error_actual`` is ``|M̂_k − m_k|`` against the number ``m_k`` of clutter plots
  actually drawn. ``M̂_k`` is the estimator's ``count_`` when it has one (``gmm``,
  ``agmm``), else ``∫_R κ̂_k`` by the same quadrature (``known``: ``κ·A``).

The true intensity of a scan is ``κ_k(z) = S·λ_k·c_k(z)``: every sensor draws its own
clutter from the scenario's model (``mhtrack.scenario.simulate``).

Pure formulas only; :func:`mhtrack.experiments.clutter_study.clutter_accuracy` runs an
estimator over a simulation and scores it with them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.models.clutter import TimeVaryingClutter
from mhtrack.scenario import Simulation

#: Default grid resolution ``n`` (cells per side) of the IAE quadrature.
DEFAULT_RESOLUTION = 400


def integrated_absolute_error(
    kappa_hat: np.ndarray, kappa: np.ndarray, cell_area: float
) -> float:
    """``Σ_i |κ̂(z_i) − κ(z_i)| ΔA`` — the midpoint rule for ``∫|κ̂ − κ| dz`` given both
    intensities at the cell centres ``z_i`` of equal cells of area ``ΔA``."""
    a = np.asarray(kappa_hat, float).reshape(-1)
    b = np.asarray(kappa, float).reshape(-1)
    if a.shape != b.shape:
        raise ValueError(f"intensity grids differ in size: {a.size} vs {b.size}")
    return float(np.abs(a - b).sum() * cell_area)


def true_intensity_grid(
    simulation: Simulation, scan: int, grid: np.ndarray, _cache: dict[str, Any] | None = None
) -> np.ndarray:
    """``κ_k(z) = S λ_k c_k(z)`` at the grid points (see the module docstring)."""
    sc = simulation.scenario
    model = sc.clutter
    s = len(sc.sensors)
    if isinstance(model, TimeVaryingClutter):
        model = model.at(scan)
        return s * model.intensity(grid, scan)
    if _cache is not None:
        if "density" not in _cache:
            _cache["density"] = model.density(grid, scan)
        return s * model.rate(scan) * _cache["density"]
    return s * model.intensity(grid, scan)


def uniform_guess(simulation: Simulation) -> float:
    """``κ = S λ̄ / A``: the scenario's true mean clutter count per scan (all sensors,
    averaged over its scans) spread uniformly over its region — the ``known`` baseline."""
    return simulation.scenario.mean_clutter_density()


def quadrature_relative_error(true: np.ndarray, cell_area: float, rate: float) -> float:
    """``|Σ_i κ(z_i) ΔA − S λ_k| / (S λ_k)``: the midpoint rule's error on the known mass
    ``S λ_k`` of the true intensity (0 when ``S λ_k = 0``)."""
    return abs(true.sum() * cell_area - rate) / rate if rate > 0 else 0.0
