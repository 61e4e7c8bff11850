"""A radar's clutter map: plot counts per range–azimuth cell, averaged over rotations with
exponential forgetting, as operational trackers keep it.

The map divides the disc around the radar's ``site`` into rings of width ``Δr`` and
``n_θ`` equal sectors of bearing (clockwise from grid north). Cell ``c`` = (ring ``i``,
sector ``j``) has the plane area

    A_c = ½ Δθ ((i+1)² − i²) Δr² = ½ Δθ (2i + 1) Δr²,      Δθ = 2π / n_θ,

so that the ``n_r`` rings' cells cover ``π (n_r Δr)²`` exactly. Each rotation ``k`` (one
call of :meth:`ClutterMap.update`; :class:`~mhtrack.clutter.per_sensor.PerSensorClutter`
gathers a rotating radar's frames into rotations) adds its plot count ``n_c,k`` to the
cell's discounted sum, and one look to the discounted number of rotations:

    S_c,k = γ S_c,k−1 + n_c,k,        N_k = γ N_k−1 + 1,        λ̂_c,k = S_c,k / N_k

— the recursive (exponentially forgetting) average of the clutter-map CFAR (Nitzberg,
"Clutter map CFAR analysis", IEEE TAES 22(4), 1986: ``q_k = (1 − w) q_k−1 + w x_k`` with
``w = 1 − γ`` once ``N_k`` has reached ``1/(1 − γ)``; normalising by ``N_k`` makes the
first rotations unbiased too). For Poisson counts of mean ``λ_c`` it is unbiased with

    Var λ̂_c,k = λ_c Σ_{m<k} γ^{2m} / (Σ_{m<k} γ^m)²  →  λ_c (1 − γ)/(1 + γ),

and after a step of the mean from ``λ₁`` to ``λ₂`` it follows
``E λ̂ = λ₂ + (λ₁ − λ₂) γ^{m}·(N before the step)/N_k`` (``m`` rotations after the step):
the memory is ``1/(1 − γ)`` rotations. Cells that saw few plots are shrunk toward the
map's mean intensity ``ρ̄ = Σ_c S_c / (N_k A)`` (a Gamma prior worth ``b₀`` rotations,
``prior_weight``; ``b₀ = 0`` is the plain average); the intensity (plots per m² per look,
the ``κ`` of the score) is

    κ̂(z) = (S̃_c / Ã_c + b₀ ρ̄) / (N_k + b₀)       for z in cell c,

``S̃``, ``Ã`` the sums and areas smoothed by ``smoothing`` passes (:data:`SMOOTHING`) of the
binomial kernel over neighbouring cells (:func:`smooth_cells`; 0 passes: ``S_c / A_c``),

and ``b₀ ρ̄ / (N_k + b₀)`` beyond the map (a cell that never held a plot). Plots that the
tracker gives to confirmed tracks are taken out of the last rotation (:meth:`forget`), as
Musicki & Evans ("Clutter map information for data association and track
initialization", IEEE TAES 40(2), 2004) estimate the clutter density from the plots no
track claims.

*Cell size.* Unless given, the cells follow the radar's reach ``R`` (``max_range``):
:data:`REACH_RINGS` rings of ``Δr = R / 24`` and :data:`REACH_SECTORS` sectors (5.625°;
cells square at ``r = Δr/Δθ ≈ 0.42 R``), so a map holds the same 1 536 cells whatever the
radar's reach, smoothed by :data:`SMOOTHING` (2) passes so that a cell's estimate draws
on its neighbours' counts over the memory. Measured on the study's scenes
(``docs/clutter.md``, *Cell size*: finer cells and smoothing 42.7 plots per rotation of
clutter error against 49.0 for the former 12 × 32 unsmoothed). Without a reach (a scan
path) the cells are 500 m × 64 sectors.

The rings grow as far plots arrive (up to ``max_rings``; plots beyond are counted in
``n_outside_``): memory ``n_r × n_θ`` floats, time per rotation linear in its plots plus
one pass over the cells.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.discount import check_discount, discount
from mhtrack.records import Scan

#: Rings over the reach and sectors of a map placed with a ``max_range`` and no
#: ``range_cell`` / ``n_azimuth`` given (module docstring, *Cell size*).
REACH_RINGS = 24
REACH_SECTORS = 64
#: Passes of :func:`smooth_cells` (measured: docs/clutter.md).
SMOOTHING = 2
#: Half-life ``h`` (s of data time) of the counts (measured: docs/clutter.md).
HALF_LIFE = 40.0
#: Cells of a map without a reach.
DEFAULT_RANGE_CELL = 500.0
DEFAULT_SECTORS = 64

Source = Literal["all", "outside-gates"]
SOURCES: tuple[str, ...] = ("all", "outside-gates")


def cell_areas(n_rings: int, n_azimuth: int, range_cell: float) -> np.ndarray:
    """(n_rings,) area (m²) of one cell of each ring: ``½ Δθ (2i + 1) Δr²``."""
    i = np.arange(int(n_rings), dtype=float)
    return 0.5 * (2.0 * np.pi / n_azimuth) * (2.0 * i + 1.0) * range_cell**2


def smooth_cells(a: np.ndarray, passes: int) -> np.ndarray:
    """``a`` (..., rings, sectors) convolved ``passes`` times with the binomial kernel
    ``[1, 2, 1]/4`` along the rings (the first and last ring reflected) and along the
    sectors (circular). The map's smoothed density is the ratio of the smoothed counts to
    the smoothed cell areas, ``Σ w S / (N Σ w A)``: a kernel-smoothed histogram (the
    averaged shifted histogram of Scott, *Ann. Statist.* 13(3), 1985, whose weights are
    these binomial ones), which keeps the map's total and trades the blocks' bias and the
    cells' Poisson variance."""
    out = np.asarray(a, float)
    for _ in range(int(passes)):
        left, right = np.empty_like(out), np.empty_like(out)  # np.roll by ±1 sector
        left[..., 1:], left[..., :1] = out[..., :-1], out[..., -1:]
        right[..., :-1], right[..., -1:] = out[..., 1:], out[..., :1]
        out = 0.5 * out + 0.25 * (left + right)
        if out.shape[-2] > 1:
            up, down = np.empty_like(out), np.empty_like(out)  # the end rings reflected
            up[..., 1:, :], up[..., :1, :] = out[..., :-1, :], out[..., :1, :]
            down[..., :-1, :], down[..., -1:, :] = out[..., 1:, :], out[..., -1:, :]
            out = 0.5 * out + 0.25 * (up + down)
    return out


def forgetting_variance_factor(gamma: float, k: int) -> float:
    """``Σ_{m<k} γ^{2m} / (Σ_{m<k} γ^m)²``: the variance of the forgetting average of ``k``
    independent counts, per unit of their (common) variance."""
    w = gamma ** np.arange(int(k), dtype=float)
    return float((w**2).sum() / w.sum() ** 2)


class ClutterMap(ClutterEstimator):
    """A radar's range–azimuth clutter map (module docstring).

    Parameters
    ----------
    site : the radar's site (x, y) in the local frame (m). Default ``(0, 0)``, the
        frame's origin (a scan path with one sensor and no site).
    range_cell : ``Δr`` (m). Default ``max_range / REACH_RINGS`` with a ``max_range``,
        else 500.
    n_azimuth : ``n_θ``, sectors of bearing. Default :data:`REACH_SECTORS` (64, 5.6°)
        with a ``max_range``, else 64 (5.6°).
    half_life : ``h`` (s of data time, ``inf``: no forgetting): each rotation discounts
        the sums by ``γ_k = 2^(−Δt_k/h)``, ``Δt_k`` the time since the previous one, so
        the memory is the same whatever the radar's period
        (:mod:`mhtrack.clutter.discount`). Default :data:`HALF_LIFE` unless ``forgetting``
        is given.
    forgetting : a constant ``γ`` in (0, 1] per rotation instead (memory ``1/(1 − γ)``
        rotations; not with ``half_life``). Default ``None``.
    prior_weight : ``b₀`` (rotations) of the shrinkage toward the map's mean. Default 1.
    smoothing : passes ``p`` of the binomial kernel over neighbouring cells (0: none;
        :func:`smooth_cells`). Default :data:`SMOOTHING`.
    max_range : rings made at once to reach this range (m); ``None``: as plots arrive.
    max_rings : most rings (bounded memory). Default 4096.
    source : ``"all"`` plots, or ``"outside-gates"`` (leave out plots in confirmed tracks'
        gates). Default ``"all"``.
    birth_scaling : ``β`` of the birth density this map drives
        (:func:`birth_scale`; 0: none). Default 0.
    forget_used : take the plots confirmed tracks used out of their cells (:meth:`forget`;
        on rotating radars :class:`~mhtrack.clutter.per_sensor.PerSensorClutter` takes them
        out of the rotation it gathers, unless this is ``False``; ``False``: keep them,
        the ablation of ``reproduce clutter-scenes``). Default True.
    """

    name = "map"

    def __init__(self, *, site: tuple[float, float] = (0.0, 0.0),
                 range_cell: float | None = None, n_azimuth: int | None = None,
                 half_life: float | None = None, forgetting: float | None = None,
                 prior_weight: float = 1.0, smoothing: int = SMOOTHING,
                 max_range: float | None = None, max_rings: int = 4096,
                 source: Source = "all", birth_scaling: float = 0.0,
                 forget_used: bool = True) -> None:
        site_t = tuple(float(v) for v in site)
        if len(site_t) != 2 or not all(np.isfinite(site_t)):
            raise ValueError(f"site must be two finite coordinates, got {site!r}")
        if max_range is not None and not (np.isfinite(max_range) and max_range > 0):
            raise ValueError(f"max_range must be finite and > 0 m, got {max_range!r}")
        self.cell_args = (range_cell, n_azimuth)  # as given: placed() re-derives the rest
        if range_cell is None:
            range_cell = DEFAULT_RANGE_CELL if max_range is None else max_range / REACH_RINGS
        if n_azimuth is None:
            n_azimuth = DEFAULT_SECTORS if max_range is None else REACH_SECTORS
        if not (np.isfinite(range_cell) and range_cell > 0):
            raise ValueError(f"range_cell must be finite and > 0 m, got {range_cell!r}")
        if not (isinstance(n_azimuth, int | np.integer) and 1 <= n_azimuth <= 65536):
            raise ValueError(f"n_azimuth must be an integer in [1, 65536], got {n_azimuth!r}")
        check_discount(forgetting, half_life)
        if forgetting is None and half_life is None:
            half_life = HALF_LIFE
        if not (np.isfinite(prior_weight) and prior_weight >= 0):
            raise ValueError(f"prior_weight must be finite and >= 0, got {prior_weight!r}")
        if not (isinstance(smoothing, int | np.integer) and 0 <= smoothing <= 64):
            raise ValueError(f"smoothing must be an integer in [0, 64], got {smoothing!r}")
        if not (isinstance(max_rings, int | np.integer) and 1 <= max_rings <= 1_000_000):
            raise ValueError(f"max_rings must be an integer in [1, 1e6], got {max_rings!r}")
        if source not in SOURCES:
            raise ValueError(f"source must be one of {SOURCES}, got {source!r}")
        if not (np.isfinite(birth_scaling) and 0.0 <= birth_scaling <= 10.0):
            raise ValueError(f"birth_scaling must be in [0, 10], got {birth_scaling!r}")
        self.site = (site_t[0], site_t[1])
        self.range_cell = float(range_cell)
        self.n_azimuth = int(n_azimuth)
        self.forgetting = None if forgetting is None else float(forgetting)
        self.half_life = None if half_life is None else float(half_life)
        self.prior_weight = float(prior_weight)
        self.smoothing = int(smoothing)
        self.max_range = None if max_range is None else float(max_range)
        self.max_rings = int(max_rings)
        self.source = source
        self.birth_scaling = float(birth_scaling)
        self.forget_used = bool(forget_used)
        n0 = 0 if max_range is None else min(int(np.ceil(max_range / range_cell - 1e-9)), max_rings)
        self.sums_ = np.zeros((n0, self.n_azimuth))
        self.looks_ = 0.0
        self.n_updates_ = 0
        self.n_outside_ = 0
        self.time_: float | None = None  # the last rotation's time
        self._map: np.ndarray | None = None  # intensity_map() until the next change
        self._last = np.zeros(0, np.int64)  # flat cell of each counted plot of the last update

    def placed(self, site: tuple[float, float], max_range: float | None = None
               ) -> ClutterMap:
        """A fresh map with this one's parameters about ``site`` (rings made out to
        ``max_range`` when given, else this map's)."""
        return ClutterMap(site=site, range_cell=self.cell_args[0], n_azimuth=self.cell_args[1],
                          half_life=self.half_life, forgetting=self.forgetting,
                          prior_weight=self.prior_weight, smoothing=self.smoothing,
                          max_range=self.max_range if max_range is None else max_range,
                          max_rings=self.max_rings, source=self.source,
                          birth_scaling=self.birth_scaling, forget_used=self.forget_used)

    # ------------------------------------------------------------------ geometry
    @property
    def n_rings(self) -> int:
        """Rings of the map now."""
        return int(self.sums_.shape[0])

    def areas(self) -> np.ndarray:
        """(n_rings, n_azimuth) cell areas ``A_c`` (m²)."""
        a = cell_areas(self.n_rings, self.n_azimuth, self.range_cell)
        return np.repeat(a[:, None], self.n_azimuth, axis=1)

    def cells(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Ring and sector of positions ``z`` (n, 2); rings may exceed the map's."""
        z = np.asarray(z, float).reshape(-1, 2)
        dx, dy = z[:, 0] - self.site[0], z[:, 1] - self.site[1]
        ring = np.floor(np.hypot(dx, dy) / self.range_cell)
        theta = np.mod(np.arctan2(dx, dy), 2.0 * np.pi)
        sector = np.minimum((theta * (self.n_azimuth / (2.0 * np.pi))).astype(np.int64),
                            self.n_azimuth - 1)
        return np.minimum(ring, float(self.max_rings)).astype(np.int64), sector

    # ------------------------------------------------------------------ ClutterEstimator
    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        """Add one rotation's plots (module docstring); ``ValueError`` for non-finite plots
        or a mask of the wrong length."""
        z = np.asarray(scan.z, float).reshape(-1, 2)
        if not np.isfinite(z).all():
            raise ValueError(f"scan {scan.index}: plots must be finite")
        if in_track_gates is not None:
            mask = np.asarray(in_track_gates, bool).reshape(-1)
            if mask.shape != (len(z),):
                raise ValueError(f"scan {scan.index}: in_track_gates has {mask.size} "
                                 f"entries, expected {len(z)}")
            if self.source == "outside-gates":
                z = z[~mask]
        ring, sector = self.cells(z)
        inside = ring < self.max_rings
        self.n_outside_ += int(np.count_nonzero(~inside))
        if inside.any() and int(ring[inside].max()) >= self.n_rings:
            grow = int(ring[inside].max()) + 1 - self.n_rings
            self.sums_ = np.vstack([self.sums_, np.zeros((grow, self.n_azimuth))])
        flat = np.where(inside, ring * self.n_azimuth + sector, -1)
        g = self._discount(float(scan.time))
        self.sums_ *= g
        counted = flat[inside]
        if counted.size:
            self.sums_.reshape(-1)[:] += np.bincount(counted, minlength=self.sums_.size)
        self.looks_ = g * self.looks_ + 1.0
        self.n_updates_ += 1
        self._last = flat
        self._map = None

    def _discount(self, t: float) -> float:
        """``γ_k`` (:func:`mhtrack.clutter.discount.discount`)."""
        last, self.time_ = self.time_, t
        return discount(last, t, forgetting=self.forgetting, half_life=self.half_life)

    def forget(self, used: np.ndarray) -> None:
        """Take the last rotation's plots that confirmed tracks used out of their cells."""
        used = np.asarray(used, bool).reshape(-1)
        if not self.forget_used or used.shape != self._last.shape or not used.any():
            return
        cells = self._last[used & (self._last >= 0)]
        if cells.size:
            flat = self.sums_.reshape(-1)
            np.subtract.at(flat, cells, 1.0)
            np.maximum(flat, 0.0, out=flat)
            self._last = np.where(used, -1, self._last)
            self._map = None

    def mean_intensity(self) -> float:
        """``ρ̄``: the map's clutter plots per look over its area (per m²); 0 before any
        rotation or on an empty map."""
        if self.looks_ == 0.0 or self.n_rings == 0:
            return 0.0
        area = np.pi * (self.n_rings * self.range_cell) ** 2
        return float(self.sums_.sum() / (self.looks_ * area))

    def intensity_map(self) -> np.ndarray:
        """(n_rings, n_azimuth) ``κ̂`` of every cell (per m² per look), computed once per
        change of the map."""
        if self.looks_ == 0.0:
            return np.zeros_like(self.sums_)
        if self._map is None:
            b0 = self.prior_weight
            p = self.smoothing
            density = (self.sums_ / self.areas() if p == 0 else
                       smooth_cells(self.sums_, p) / smooth_cells(self.areas(), p))
            self._map = (density + b0 * self.mean_intensity()) / (self.looks_ + b0)
        return self._map

    def intensity(self, z: np.ndarray) -> np.ndarray:
        """``κ̂(z)`` (module docstring), plots per m² per look; 0 before any rotation."""
        z = np.asarray(z, float).reshape(-1, 2)
        if not np.isfinite(z).all():
            raise ValueError("intensity: positions must be finite")
        if self.looks_ == 0.0:
            return np.zeros(len(z))
        b0 = self.prior_weight
        out = np.full(len(z), b0 * self.mean_intensity() / (self.looks_ + b0))
        ring, sector = self.cells(z)
        inside = ring < self.n_rings
        if inside.any():
            out[inside] = self.intensity_map()[ring[inside], sector[inside]]
        return out

    def reference_intensity(self) -> float:
        """The clutter level the birth scaling compares a cell with: ``ρ̄``."""
        return self.mean_intensity()

    def get_state(self) -> dict[str, Any]:
        return {"sums": self.sums_.copy(), "looks": float(self.looks_),
                "n_updates": int(self.n_updates_), "n_outside": int(self.n_outside_),
                "last": self._last.copy(), "time": self.time_}

    def set_state(self, state: dict[str, Any]) -> None:
        from mhtrack.clutter.state_checks import check_map

        sums, looks, last, t = check_map(state, self.n_azimuth, self.max_rings,
                                         self.forgetting or 1.0)
        self.sums_ = sums
        self.looks_ = looks
        self.n_updates_ = int(state["n_updates"])
        self.n_outside_ = int(state["n_outside"])
        self._last = last
        self.time_, self._map = t, None


@dataclass(frozen=True)
class MapSnapshot:
    """A clutter map at one time, for drawing: its site, ring width, and ``intensity``
    (n_rings, n_azimuth) per m² per look; ``time`` of the last scan it was fed."""

    site: tuple[float, float]
    range_cell: float
    intensity: np.ndarray
    time: float

    def edges(self) -> tuple[np.ndarray, np.ndarray]:
        """(n_rings + 1, n_azimuth + 1) x and y of the cells' corners."""
        n_r, n_a = self.intensity.shape
        r = np.arange(n_r + 1) * self.range_cell
        t = np.linspace(0.0, 2.0 * np.pi, n_a + 1)
        return (self.site[0] + r[:, None] * np.sin(t)[None, :],
                self.site[1] + r[:, None] * np.cos(t)[None, :])


def map_snapshots(clutter: ClutterEstimator, time: float) -> dict[int, MapSnapshot]:
    """The clutter maps an estimator holds, by sensor id: a :class:`ClutterMap` (id 0) or
    each fed map of a :class:`~mhtrack.clutter.per_sensor.PerSensorClutter`."""
    from mhtrack.clutter.per_sensor import PerSensorClutter

    maps: dict[int, ClutterEstimator] = {0: clutter}
    if isinstance(clutter, PerSensorClutter):
        maps = {i: clutter.estimator(i) for i in sorted(clutter._inner)
                if clutter.has_estimate(i)}
    return {i: MapSnapshot(m.site, m.range_cell, m.intensity_map(), float(time))
            for i, m in maps.items() if isinstance(m, ClutterMap)}


def birth_scale(kappa: np.ndarray, reference: float, beta: float) -> np.ndarray:
    """Factor ``s(z) = min(1, ρ̄ / κ̂(z))^β`` on the new-target density ``λ_v`` of a plot
    where the clutter map is denser than its mean ``ρ̄`` (1 where it is not, or before the
    map has a mean). Ours: the operational rule of raising the initiation threshold in
    dense clutter-map cells (Musicki & Evans 2004, §IV, use the map's density in the
    initial probability of target existence), written as a birth density so that the
    score's ``ln λ_v`` drops by ``β ln(κ̂/ρ̄)`` there."""
    k = np.asarray(kappa, float)
    if not (reference > 0 and beta > 0):
        return np.ones_like(k)
    with np.errstate(divide="ignore"):
        return np.minimum(1.0, reference / np.maximum(k, 1e-300)) ** beta
