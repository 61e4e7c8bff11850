"""A mixture calibrated by a clutter map: the GMM's shape, corrected cell by cell by the
plots a range–azimuth map counts.

A Gaussian mixture (:mod:`mhtrack.clutter.gmm`) estimates a smooth clutter shape from few
plots, but not the shapes it cannot fit with a few Gaussians (ground clutter lobed in
bearing, a sea band flat across a sector, a burst's sector edges); a clutter map
(:mod:`mhtrack.clutter.radar_map`) fits any shape at its cells' resolution, but with each
cell's Poisson noise. Here the mixture is the *parametric start* and the map estimates the
ratio of the true intensity to it (Hjort & Glad, "Nonparametric density estimation with a
parametric start", *Ann. Statist.* 23(3), 1995: ``f̂ = f_θ̂ · r̂``). Per cell ``c`` of the
map, with the same discount ``γ_k`` as the map (half-life in seconds of data time),

    S_c ← γ_k S_c + n_c,k           (the plots counted in the cell),
    E_c ← γ_k E_c + ∫_c κ̂_base,k       (the plots the base expects there),

and the ratio is the Poisson–Gamma (empirical Bayes) estimate of a relative rate from
observed and expected counts (Clayton & Kaldor, "Empirical Bayes estimates of
age-standardized relative risks for use in disease mapping", *Biometrics* 43(3), 1987):
``S_c ~ Poisson(r_c E_c)``, ``r_c ~ Gamma(b, b)`` give

    r̂_c = (S̃_c + φ b) / (Ẽ_c + φ b),       κ̂(z) = κ̂_base(z) · r̂_c(z),

``φ = Σ γ^{2m} / Σ γ^m`` the variance factor of the discounted sums, and ``φ b`` estimated
each rotation from the over-dispersion of ``S`` against ``E``
(:func:`mhtrack.clutter.shrinkage.prior_count`: infinite — every ratio 1, the base
unchanged — when the counts are consistent with Poisson(``E``)), or fixed
(``prior_count``, the ablation). ``S̃``, ``Ẽ`` the counts smoothed over neighbouring cells
(:func:`~mhtrack.clutter.radar_map.smooth_cells`, ``smoothing`` passes; the dispersion is
measured on the unsmoothed counts). ``E``'s integral (:meth:`MapCalibratedClutter.expected`)
for a Gaussian-mixture base, in the plane or in range and bearing, is the quadrature of
:mod:`mhtrack.clutter.cell_mass` (PolarClutter's ``min_range`` floor included); any other
base by the midpoint rule ``κ̂_base(x_c) A_c``. Beyond the map ``κ̂ = κ̂_base``. Plots that
confirmed tracks used are taken out of ``S`` (:meth:`forget`) and not of ``E``: ``E`` is
the base's expectation of clutter, and the base drops them from its next fits itself.
The cells' reference level ``ρ̄`` (:meth:`reference_intensity`) is the map's mean, so that
the map can drive the birth density too (``birth_scaling``).

Cost per rotation: the base's update, the quadrature (one vectorised pass over the
Gaussians' boxes, again only when the base's mixture or count changed), one pass over
the cells.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.clutter import cell_mass
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.mixture import MixtureClutter
from mhtrack.clutter.polar import PolarClutter
from mhtrack.clutter.radar_map import ClutterMap, smooth_cells
from mhtrack.clutter.shrinkage import prior_count as estimated_prior_count
from mhtrack.clutter.shrinkage import shrunk_ratio
from mhtrack.kernels import same_floats
from mhtrack.records import Scan

#: Smoothing passes over the cells (measured: docs/clutter.md).
SMOOTHING = 1
#: Rings over the reach and sectors of the cells, unless given (measured: docs/clutter.md;
#: coarser than the plain map's, as the base gives the shape within a cell).
RINGS, SECTORS = 12, 32
#: Cells without a reach (a scan path): 1 km × 32 sectors (measured, docs/clutter.md: the
#: clutter error of ``crossing-changing`` 20.53 against 20.67 with the plain map's
#: 500 m × 64, at 1.57× the GMM's time instead of 1.68×).
SCAN_RANGE_CELL, SCAN_SECTORS = 1000.0, 32


class MapCalibratedClutter(ClutterEstimator):
    """A GMM calibrated cell by cell by a range–azimuth clutter map,
    ``κ̂ = κ̂_GMM · r̂_c`` (module docstring).

    Parameters
    ----------
    base : the parametric start (any estimator; default a
        :class:`~mhtrack.clutter.gmm.GMMClutter` with ``base_params``).
    base_params : keywords of the default base.
    site, range_cell, n_azimuth, max_range, max_rings, half_life, forgetting : the cells
        and the discount, as :class:`~mhtrack.clutter.radar_map.ClutterMap`'s, but with a
        ``max_range`` the cells are :data:`RINGS` rings by :data:`SECTORS` sectors, without
        :data:`SCAN_RANGE_CELL` by :data:`SCAN_SECTORS`.
    prior_count : a fixed ``φ b`` (expected plots), the shrinkage of each ratio toward 1;
        default ``None``: estimated each rotation (module docstring).
    smoothing : passes of :func:`~mhtrack.clutter.radar_map.smooth_cells` over ``S`` and
        ``E``. Default :data:`SMOOTHING`.
    birth_scaling : ``β`` of the birth density the map drives (0: none). Default 0.
    """

    name = "mapgmm"

    def __init__(self, *, base: ClutterEstimator | None = None,
                 base_params: dict[str, Any] | None = None,
                 site: tuple[float, float] = (0.0, 0.0), range_cell: float | None = None,
                 n_azimuth: int | None = None, max_range: float | None = None,
                 max_rings: int = 4096, half_life: float | None = None,
                 forgetting: float | None = None, prior_count: float | None = None,
                 smoothing: int = SMOOTHING, birth_scaling: float = 0.0) -> None:
        if prior_count is not None and not (np.isfinite(prior_count) and prior_count > 0):
            raise ValueError(f"prior_count must be finite and > 0, got {prior_count!r}")
        if base is None:
            from mhtrack.clutter.gmm import GMMClutter

            base = GMMClutter(**(base_params or {}))
        self.base = base
        self.base_params = dict(base_params or {})
        self.cell_args = (range_cell, n_azimuth)  # as given: placed() re-derives the rest
        if range_cell is None:
            range_cell = SCAN_RANGE_CELL if max_range is None else max_range / RINGS
        if n_azimuth is None:
            n_azimuth = SCAN_SECTORS if max_range is None else SECTORS
        self.counts = ClutterMap(site=site, range_cell=range_cell, n_azimuth=n_azimuth,
                                 max_range=max_range, max_rings=max_rings,
                                 half_life=half_life, forgetting=forgetting,
                                 prior_weight=0.0, birth_scaling=birth_scaling)
        self.prior_count = None if prior_count is None else float(prior_count)
        self.smoothing = int(smoothing)
        if not 0 <= self.smoothing <= 64:
            raise ValueError(f"smoothing must be an integer in [0, 64], got {smoothing!r}")
        self.expected_ = np.zeros_like(self.counts.sums_)
        self.looks2_ = 0.0  # Σ γ^{2m}, for φ
        self._ratio: np.ndarray | None = None
        self._centres = np.zeros((0, 2))
        self._nodes: tuple[cell_mass.Cells, tuple[np.ndarray, ...]] | None = None
        self._last: tuple[Any, float, int, np.ndarray] | None = None  # mixture, M̂, rings, E
        self._background: tuple[Any, np.ndarray] | None = None  # (box, rings), ∫_c u
        self._scan_cells: tuple[np.ndarray, np.ndarray] | None = None  # last plots, cells

    @property
    def site(self) -> tuple[float, float]:
        return self.counts.site

    @property
    def range_cell(self) -> float:
        return self.counts.range_cell

    def placed(self, site: tuple[float, float], max_range: float | None = None,
               base: ClutterEstimator | None = None) -> MapCalibratedClutter:
        """A fresh estimator with these parameters about ``site`` (rings out to
        ``max_range``), calibrating ``base`` (default: a fresh default base)."""
        c = self.counts
        return MapCalibratedClutter(
            base=base, base_params=self.base_params, site=site, range_cell=self.cell_args[0],
            n_azimuth=self.cell_args[1], max_range=c.max_range if max_range is None else max_range,
            max_rings=c.max_rings, half_life=c.half_life, forgetting=c.forgetting,
            prior_count=self.prior_count, smoothing=self.smoothing,
            birth_scaling=c.birth_scaling)

    def centres(self) -> np.ndarray:
        """(n_rings·n_azimuth, 2) plane centres of the map's cells, ring-major (made
        again only when rings are added)."""
        c = self.counts
        if len(self._centres) == c.sums_.size:
            return self._centres
        r = (np.arange(c.n_rings) + 0.5) * c.range_cell
        t = (np.arange(c.n_azimuth) + 0.5) * (2.0 * np.pi / c.n_azimuth)
        x = c.site[0] + r[:, None] * np.sin(t)[None, :]
        y = c.site[1] + r[:, None] * np.cos(t)[None, :]
        self._centres = np.column_stack([x.reshape(-1), y.reshape(-1)])
        return self._centres

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        """The base's update, then the map's counts and the base's expected counts."""
        self.base.update(scan, in_track_gates)
        c = self.counts
        looks = c.looks_
        c.update(scan, in_track_gates)
        self._scan_cells = (np.asarray(scan.z, float).reshape(-1, 2), c._last.copy())
        g = (c.looks_ - 1.0) / looks if looks > 0 else 1.0  # the map's γ_k
        self.looks2_ = g * g * self.looks2_ + 1.0
        grow = c.n_rings - self.expected_.shape[0]
        if grow > 0:
            self.expected_ = np.vstack([self.expected_, np.zeros((grow, c.n_azimuth))])
        self.expected_ = g * self.expected_ + self.expected()
        self._ratio = None

    def _cells(self) -> tuple[cell_mass.Cells, tuple[np.ndarray, ...]]:
        """The map's geometry in the base's coordinates and its cells' quadrature nodes
        (made again only when rings are added)."""
        c, base = self.counts, self.base
        if self._nodes is None or self._nodes[0].n_rings != c.n_rings:
            polar = ((base.r0, base.min_range, float(base.cut))
                     if isinstance(base, PolarClutter) else None)
            cells = cell_mass.Cells(c.site, c.range_cell, c.n_rings, c.n_azimuth, polar)
            self._nodes = (cells, cell_mass.cell_nodes(cells))
        return self._nodes

    def expected(self) -> np.ndarray:
        """(n_rings, n_azimuth) ``∫_c κ̂_base`` now, the plots the base expects per cell
        (module docstring); the last result again while the base's mixture, count and the
        rings are unchanged."""
        c, base = self.counts, self.base
        inner = base.inner if isinstance(base, PolarClutter) else base
        mix = getattr(inner, "mixture_", None)
        if not isinstance(inner, MixtureClutter) or mix is None or not len(mix.weights):
            mid = np.asarray(base.intensity(self.centres()), float)
            return mid.reshape(c.sums_.shape) * c.areas()
        last = self._last
        if (last is not None and last[0] is mix and last[1] == inner.count_
                and last[2] == c.n_rings):
            return last[3]
        cells, nodes = self._cells()
        out = cell_mass.mixture_mass(cells, mix.weights, mix.means, mix.covariances)
        box = mix.background_box
        if box is not None and mix.background_weight > 0:
            if self._background is None or self._background[0] != (box, c.n_rings):
                self._background = ((box, c.n_rings),
                                    cell_mass.background_mass(cells, nodes, box))
            out += mix.background_weight * self._background[1]
        e = inner.count_ * out.reshape(c.sums_.shape)
        self._last = (mix, inner.count_, c.n_rings, e)
        return e

    def prior(self) -> float:
        """``φ b``: the fixed ``prior_count``, else estimated from the unsmoothed counts
        (:func:`mhtrack.clutter.shrinkage.prior_count`; ``inf``: no correction)."""
        if self.prior_count is not None:
            return self.prior_count
        looks = self.counts.looks_
        phi = self.looks2_ / looks if looks > 0 else 1.0
        return estimated_prior_count(self.counts.sums_, self.expected_, phi)

    def ratio(self) -> np.ndarray:
        """(n_rings, n_azimuth) ``r̂_c`` (module docstring), computed once per change."""
        if self._ratio is None:
            p, b = self.smoothing, self.prior()
            s, e = self.counts.sums_, self.expected_
            if p and np.isfinite(b):
                s, e = smooth_cells(np.stack([s, e]), p)
            self._ratio = shrunk_ratio(s, e, b)
        return self._ratio

    def intensity(self, z: np.ndarray) -> np.ndarray:
        """``κ̂_base(z) · r̂_c(z)`` per m² per scan (``κ̂_base`` beyond the map)."""
        z = np.asarray(z, float).reshape(-1, 2)
        out = np.asarray(self.base.intensity(z), float).copy()
        c = self.counts
        if c.looks_ == 0.0 or not c.n_rings:
            return out
        last = self._scan_cells
        if last is not None and same_floats(last[0], z):  # the scan's own plots: cells known
            flat = last[1]
            inside = flat >= 0
            out[inside] *= self.ratio().reshape(-1)[flat[inside]]
            return out
        ring, sector = c.cells(z)
        inside = ring < c.n_rings
        out[inside] *= self.ratio()[ring[inside], sector[inside]]
        return out

    def forget(self, used: np.ndarray) -> None:
        self.base.forget(used)
        self.counts.forget(used)
        self._ratio = None

    def reference_intensity(self) -> float:
        """The map's mean intensity ``ρ̄`` (for the birth scaling)."""
        return self.counts.mean_intensity()

    def get_state(self) -> dict[str, Any]:
        return {"base": self.base.get_state(), "counts": self.counts.get_state(),
                "expected": self.expected_.copy(), "looks2": float(self.looks2_)}

    def set_state(self, state: dict[str, Any]) -> None:
        from mhtrack.clutter.state_checks import array

        self.base.set_state(state["base"])
        self.counts.set_state(state["counts"])
        e = np.asarray(array(state["expected"], "clutter_state.expected",
                             (-1, self.counts.n_azimuth)), float)
        if e.shape != self.counts.sums_.shape or (e < 0).any():
            raise ValueError("field clutter_state.expected: expected counts of the map's "
                             f"shape {self.counts.sums_.shape}, each >= 0")
        looks2 = float(state["looks2"])
        if not (np.isfinite(looks2) and 0.0 <= looks2 <= max(self.counts.looks_, 1.0)):
            raise ValueError("field clutter_state.looks2: expected a finite Σγ^2m in "
                             f"[0, looks], got {looks2!r}")
        self.expected_, self._ratio = np.ascontiguousarray(e), None
        self.looks2_, self._last, self._scan_cells = looks2, None, None
