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
observed and expected counts, shrunk toward 1 by a prior worth ``b₀`` expected plots
(Clayton & Kaldor, "Empirical Bayes estimates of age-standardized relative risks for use
in disease mapping", *Biometrics* 43(3), 1987): ``S_c ~ Poisson(r_c E_c)``,
``r_c ~ Gamma(b₀, b₀)`` give

    r̂_c = (S̃_c + b₀) / (Ẽ_c + b₀),       κ̂(z) = κ̂_base(z) · r̂_c(z),

``E``'s integral (:meth:`MapCalibratedClutter.expected`): for a Gaussian-mixture base
(``κ̂ = M̂ (π₀ u + Σ_j π_j N_j)``, in the plane or in range and bearing) each Gaussian's
mass per cell by the midpoint rule ``N_j(x_c)·A_c`` when the cells resolve it (its σ
along range and across bearing at least :data:`RESOLVED` times the cell's sides there),
else by the 7 × 7 Gauss–Hermite nodes ``μ_j + L_j ξ_q`` each put with its weight into
its cell (a clump narrower than a cell, which the midpoint rule would miss or blow up);
the background and any other base by the midpoint rule. ``S̃``, ``Ẽ`` the
counts smoothed over neighbouring cells
(:func:`~mhtrack.clutter.radar_map.smooth_cells`, ``smoothing`` passes). Beyond the map
``κ̂ = κ̂_base``. Plots that confirmed tracks used are taken out of both (:meth:`forget`).
The cells' reference level ``ρ̄`` (:meth:`reference_intensity`) is the map's mean, so that
the map can drive the birth density too (``birth_scaling``).

Cost per rotation: the base's update, plus the base's intensity at the map's cell centres
and one pass over the cells.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.density import Mixture
from mhtrack.clutter.radar_map import ClutterMap, smooth_cells
from mhtrack.records import Scan

#: ``b₀``, expected plots of the prior on each cell's ratio (measured: docs/clutter.md).
PRIOR_COUNT = 5.0
#: Smoothing passes over the cells (measured: docs/clutter.md).
SMOOTHING = 1
#: A Gaussian is resolved by the cells when its σ along each of the cell's axes is at
#: least this times the cell's side (the midpoint rule's error is then small).
RESOLVED = 0.5
#: Rings over the reach and sectors of the cells, unless given (measured: docs/clutter.md;
#: coarser than the plain map's, as the base gives the shape within a cell).
RINGS, SECTORS = 12, 32


def _gauss_hermite(n: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """(n², 2) nodes ``ξ`` and weights (sum 1) of the n × n probabilists' Gauss–Hermite
    product rule for ``E f(ξ)``, ``ξ ~ N(0, I)`` (Abramowitz & Stegun 25.4.46)."""
    x, w = np.polynomial.hermite_e.hermegauss(n)
    w = w / w.sum()
    gx, gy = np.meshgrid(x, x, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()]), np.outer(w, w).ravel()


_NODES = _gauss_hermite()


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
        ``max_range`` the cells are :data:`RINGS` rings by :data:`SECTORS` sectors.
    prior_count : ``b₀`` (expected plots), the shrinkage of each ratio toward 1. Default
        :data:`PRIOR_COUNT`.
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
                 forgetting: float | None = None, prior_count: float = PRIOR_COUNT,
                 smoothing: int = SMOOTHING, birth_scaling: float = 0.0) -> None:
        if not (np.isfinite(prior_count) and prior_count > 0):
            raise ValueError(f"prior_count must be finite and > 0, got {prior_count!r}")
        if base is None:
            from mhtrack.clutter.gmm import GMMClutter

            base = GMMClutter(**(base_params or {}))
        self.base = base
        self.base_params = dict(base_params or {})
        self.cell_args = (range_cell, n_azimuth)  # as given: placed() re-derives the rest
        if max_range is not None:
            range_cell = max_range / RINGS if range_cell is None else range_cell
            n_azimuth = SECTORS if n_azimuth is None else n_azimuth
        self.counts = ClutterMap(site=site, range_cell=range_cell, n_azimuth=n_azimuth,
                                 max_range=max_range, max_rings=max_rings,
                                 half_life=half_life, forgetting=forgetting,
                                 prior_weight=0.0, birth_scaling=birth_scaling)
        self.prior_count = float(prior_count)
        self.smoothing = int(smoothing)
        if not 0 <= self.smoothing <= 64:
            raise ValueError(f"smoothing must be an integer in [0, 64], got {smoothing!r}")
        self.expected_ = np.zeros_like(self.counts.sums_)
        self._ratio: np.ndarray | None = None
        self._centres = np.zeros((0, 2))
        self._polar_centres = np.zeros((0, 2))

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

    def _base_centres(self, polar: bool) -> np.ndarray:
        """The cells' centres in the base's coordinates (range and bearing for a
        :class:`~mhtrack.clutter.polar.PolarClutter` base), made again only when rings are
        added."""
        xy = self.centres()
        if not polar:
            return xy
        if len(self._polar_centres) != len(xy):
            self._polar_centres = self.base.to_polar(xy)  # type: ignore[attr-defined]
        return self._polar_centres

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        """The base's update, then the map's counts and the base's expected counts."""
        self.base.update(scan, in_track_gates)
        c = self.counts
        looks = c.looks_
        c.update(scan, in_track_gates)
        g = (c.looks_ - 1.0) / looks if looks > 0 else 1.0  # the map's γ_k
        grow = c.n_rings - self.expected_.shape[0]
        if grow > 0:
            self.expected_ = np.vstack([self.expected_, np.zeros((grow, c.n_azimuth))])
        self.expected_ = g * self.expected_ + self.expected()
        self._ratio = None

    def expected(self) -> np.ndarray:
        """(n_rings, n_azimuth) ``∫_c κ̂_base`` now, the plots the base expects per cell
        (module docstring)."""
        from mhtrack.clutter.mixture import MixtureClutter
        from mhtrack.clutter.polar import PolarClutter

        c, base = self.counts, self.base
        polar = isinstance(base, PolarClutter)
        inner = base.inner if polar else base
        mix = getattr(inner, "mixture_", None)
        if not isinstance(inner, MixtureClutter) or mix is None or not len(mix.weights):
            mid = np.asarray(base.intensity(self.centres()), float)
            return mid.reshape(c.sums_.shape) * c.areas()
        pts = self._base_centres(polar)
        d_theta = 2.0 * np.pi / c.n_azimuth
        # cell sides and areas in the base's coordinates
        if polar:
            r0 = base.r0  # type: ignore[attr-defined]
            area_b = np.full(c.sums_.shape, c.range_cell * r0 * d_theta)
        else:
            area_b = c.areas()
        cov, means = mix.covariances, mix.means
        if polar:  # cells are Δr by r₀Δθ rectangles in the base's coordinates
            sd_a, sd_b = np.sqrt(cov[:, 0, 0]), np.sqrt(cov[:, 1, 1])
            side_a, side_b = c.range_cell, np.full(len(means), r0 * d_theta)
        else:  # along and across the bearing at the Gaussian's mean
            d = means - np.asarray(c.site)
            u = d / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)[:, None]
            v = np.column_stack([-u[:, 1], u[:, 0]])
            sd_a = np.sqrt(np.einsum("ki,kij,kj->k", u, cov, u))
            sd_b = np.sqrt(np.einsum("ki,kij,kj->k", v, cov, v))
            side_b = np.maximum(np.hypot(d[:, 0], d[:, 1]), 0.5 * c.range_cell) * d_theta
            side_a = c.range_cell
        resolved = (sd_a >= RESOLVED * side_a) & (sd_b >= RESOLVED * side_b)
        out = np.zeros(c.sums_.size)
        if resolved.any():
            sub = Mixture(mix.weights[resolved], means[resolved], cov[resolved])
            out += sub.pdf(pts) * area_b.reshape(-1)
        if not resolved.all():  # Gauss–Hermite nodes μ + Lξ, each with its mass
            nodes, w = _NODES
            low = np.flatnonzero(~resolved)
            chol = np.linalg.cholesky(cov[low])
            x = means[low, None, :] + np.einsum("kij,qj->kqi", chol, nodes)
            mass = mix.weights[low, None] * w[None, :]
            x = x.reshape(-1, 2)
            if polar:
                theta = x[:, 1] / r0 + base.cut  # type: ignore[attr-defined]
                x = np.column_stack([c.site[0] + x[:, 0] * np.sin(theta),
                                     c.site[1] + x[:, 0] * np.cos(theta)])
            ring, sector = c.cells(x)
            inside = ring < c.n_rings
            np.add.at(out, ring[inside] * c.n_azimuth + sector[inside],
                      mass.reshape(-1)[inside])
        if mix.background_box is not None and mix.background_weight > 0:
            x0, x1, y0, y1 = mix.background_box
            inbox = ((pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0)
                     & (pts[:, 1] <= y1))
            out += np.where(inbox, mix.background_weight / mix.background_area, 0.0) \
                * area_b.reshape(-1)
        return inner.count_ * out.reshape(c.sums_.shape)

    def ratio(self) -> np.ndarray:
        """(n_rings, n_azimuth) ``r̂_c`` (module docstring), computed once per change."""
        if self._ratio is None:
            p, b0 = self.smoothing, self.prior_count
            s, e = self.counts.sums_, self.expected_
            if p:
                s, e = smooth_cells(s, p), smooth_cells(e, p)
            self._ratio = (s + b0) / (e + b0)
        return self._ratio

    def intensity(self, z: np.ndarray) -> np.ndarray:
        """``κ̂_base(z) · r̂_c(z)`` per m² per scan (``κ̂_base`` beyond the map)."""
        z = np.asarray(z, float).reshape(-1, 2)
        out = np.asarray(self.base.intensity(z), float).copy()
        c = self.counts
        if c.looks_ == 0.0 or not c.n_rings:
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
                "expected": self.expected_.copy()}

    def set_state(self, state: dict[str, Any]) -> None:
        from mhtrack.clutter.state_checks import array

        self.base.set_state(state["base"])
        self.counts.set_state(state["counts"])
        e = np.asarray(array(state["expected"], "clutter_state.expected",
                             (-1, self.counts.n_azimuth)), float)
        if e.shape != self.counts.sums_.shape or (e < 0).any():
            raise ValueError("field clutter_state.expected: expected counts of the map's "
                             f"shape {self.counts.sums_.shape}, each >= 0")
        self.expected_, self._ratio = np.ascontiguousarray(e), None
