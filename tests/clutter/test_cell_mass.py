"""The plots a mixture puts in each range–azimuth cell (``mhtrack.clutter.cell_mass``, the
``E`` of the map-calibrated GMM) against a fine midpoint grid in range and bearing (60 × 60
points per cell, ``∫∫ κ r dr dθ``), in the plane and in PolarClutter's range and bearing."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.clutter import cell_mass
from mhtrack.clutter.calibrated import MapCalibratedClutter
from mhtrack.clutter.gmm import GMMClutter
from mhtrack.clutter.polar import PolarClutter
from mhtrack.records import Scan

FINE = 60
#: Tolerance per cell, as a fraction of the mixture's mass in the map (the quadrature's
#: 2-node rule on steps of at most 2σ: < 1 % of a Gaussian's mass).
TOL = 0.01


def _fine(cells: cell_mass.Cells, kappa) -> np.ndarray:
    """(rings, sectors) ``∫_c κ dA`` by the midpoint rule on FINE × FINE sub-cells."""
    u = (np.arange(FINE) + 0.5) / FINE
    r = ((np.arange(cells.n_rings)[:, None] + u[None, :]) * cells.dr).reshape(-1)
    t = ((np.arange(cells.n_azimuth)[:, None] + u[None, :]) * cells.dtheta).reshape(-1)
    rr, tt = np.meshgrid(r, t, indexing="ij")
    x = cells.site[0] + rr * np.sin(tt)
    y = cells.site[1] + rr * np.cos(tt)
    f = kappa(x.reshape(-1), y.reshape(-1), rr.reshape(-1), tt.reshape(-1)).reshape(rr.shape)
    f = f * rr * (cells.dr / FINE) * (cells.dtheta / FINE)
    return f.reshape(cells.n_rings, FINE, cells.n_azimuth, FINE).sum(axis=(1, 3))


def _gauss(x: np.ndarray, y: np.ndarray, mean, cov) -> np.ndarray:
    d = np.column_stack([x - mean[0], y - mean[1]])
    q = np.einsum("ni,ij,nj->n", d, np.linalg.inv(cov), d)
    return np.exp(-0.5 * q) / (2 * np.pi * np.sqrt(np.linalg.det(cov)))


def _mass(cells: cell_mass.Cells, w, means, covs) -> np.ndarray:
    w, means, covs = (np.asarray(a, float) for a in (w, means, covs))
    out = cell_mass.mixture_mass(cells, w, means, covs)
    return out.reshape(cells.n_rings, cells.n_azimuth)


@pytest.mark.parametrize("sigma", [150.0, 400.0, 900.0, 3000.0])
def test_plane_clump_across_a_sector_edge_matches_the_fine_grid(sigma: float) -> None:
    """A plane Gaussian centred on a sector edge and a ring edge at 8 km (cells 1 km ×
    11.25°, ~1.6 km across there), narrow to broad, and a second one tilted: every cell
    within :data:`TOL` of the mixture's mass (the former midpoint rule: ~15 % off)."""
    cells = cell_mass.Cells((100.0, -50.0), 1000.0, 14, 32)
    edge = 5 * cells.dtheta
    means = [[100.0 + 8000.0 * np.sin(edge), -50.0 + 8000.0 * np.cos(edge)],
             [100.0 - 5000.0, -50.0 + 2500.0]]
    covs = [np.eye(2) * sigma**2, [[sigma**2, 0.6 * sigma**2], [0.6 * sigma**2, 2 * sigma**2]]]
    w = [0.6, 0.3]
    got = _mass(cells, w, means, covs)
    ref = _fine(cells, lambda x, y, r, t: sum(
        wi * _gauss(x, y, m, c) for wi, m, c in zip(w, means, covs, strict=True)))
    assert np.abs(got - ref).max() < TOL * ref.sum()
    assert got.sum() == pytest.approx(ref.sum(), rel=TOL)


def _polar_kappa(w, means, covs, r0, rmin, cut):
    def kappa(x, y, r, t):
        s = r0 * np.mod(t - cut, 2 * np.pi)
        dens = sum(wi * _gauss(r, s, m, c) for wi, m, c in zip(w, means, covs, strict=True))
        return dens * r0 / np.maximum(r, rmin)
    return kappa


@pytest.mark.parametrize("sigma", [400.0, 2500.0])
def test_plane_clump_centred_on_the_site_matches_the_fine_grid(sigma: float) -> None:
    """A plane Gaussian whose mean is the site itself (no bearing of its own: the whole
    circle), correlated: every cell within :data:`TOL` of the fine grid, no warning."""
    cells = cell_mass.Cells((250.0, 400.0), 500.0, 12, 16)
    cov = np.array([[sigma**2, 0.5 * sigma**2], [0.5 * sigma**2, 1.5 * sigma**2]])
    got = _mass(cells, [1.0], [cells.site], [cov])
    ref = _fine(cells, lambda x, y, r, t: _gauss(x, y, cells.site, cov))
    assert np.abs(got - ref).max() < TOL * ref.sum()
    assert got.sum() == pytest.approx(ref.sum(), rel=TOL)


@pytest.mark.parametrize("mu_r", [300.0, 1500.0, 6000.0])
def test_polar_mixture_near_the_site_keeps_min_range_and_no_negative_ranges(mu_r: float
                                                                             ) -> None:
    """PolarClutter's plane intensity ``κ_polar(r, r₀θ) r₀ / max(r, r_min)``: a Gaussian at
    range ``mu_r`` (σ_r 700 m, so part of it at ``r < 0``, which the plane never sees)
    and a broad one; every cell, ring 0 included, within :data:`TOL` of the fine grid —
    no mass in the opposite bearing, ``r_min``'s floor counted."""
    r0, rmin, cut = 100_000.0, 1000.0, np.pi
    cells = cell_mass.Cells((0.0, 0.0), 2000.0, 8, 16, (r0, rmin, cut))
    means = [[mu_r, r0 * 0.6], [5000.0, r0 * 3.0]]
    covs = [np.diag([700.0**2, (r0 * 0.1) ** 2]), np.diag([4000.0**2, (r0 * 1.5) ** 2])]
    w = [0.5, 0.4]
    got = _mass(cells, w, means, covs)
    ref = _fine(cells, _polar_kappa(w, means, covs, r0, rmin, cut))
    assert np.abs(got - ref).max() < TOL * ref.sum()
    opposite = (np.arange(16) + 8) % 16  # the sectors across the site from the clump
    assert got[0, opposite[:3]].sum() == pytest.approx(ref[0, opposite[:3]].sum(),
                                                       abs=TOL * ref.sum())


def test_map_calibrated_expected_counts_near_the_radar_match_brute_force() -> None:
    """The estimator's ``E`` after one rotation of ground clutter near the site (GMM in
    range and bearing, PolarClutter's default ``min_range`` 1 km, cells 1 km × 32):
    ring by ring within 2 % of the fine-grid integral of the base's own plane intensity
    (ring 0 was 2.3 × too high before the floor was counted)."""
    rng = np.random.default_rng(3)
    r = np.abs(rng.normal(1200.0, 600.0, 300))
    t = rng.normal(0.7, 0.3, 300)
    z = np.column_stack([r * np.sin(t), r * np.cos(t)])
    far = rng.uniform(-15e3, 15e3, (200, 2))
    z = np.vstack([z, far[np.hypot(far[:, 0], far[:, 1]) < 15e3]])
    base = PolarClutter(GMMClutter(window=1), (0.0, 0.0))
    est = MapCalibratedClutter(base=base, range_cell=1000.0, n_azimuth=32, max_range=15e3)
    est.update(Scan(0, 0.0, z, np.zeros(len(z), np.int64), np.arange(len(z))))
    cells = cell_mass.Cells((0.0, 0.0), 1000.0, 15, 32, (base.r0, base.min_range, base.cut))
    ref = _fine(cells, lambda x, y, rr, tt: base.intensity(np.column_stack([x, y])))
    np.testing.assert_allclose(est.expected_.sum(axis=1), ref.sum(axis=1), rtol=0.02)
    assert np.abs(est.expected_ - ref).max() < TOL * ref.sum()
