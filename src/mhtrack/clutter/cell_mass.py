"""The plots a Gaussian-mixture clutter intensity puts in each cell of a range–azimuth map,
``E_c = ∫_c κ̂ dA``, by Gauss–Legendre quadrature in the cell's range and bearing.

A map's cell ``c`` is ``r ∈ [iΔr, (i+1)Δr)``, ``θ ∈ [jΔθ, (j+1)Δθ)`` about the site (grid
bearing, clockwise from north), so that ``∫_c κ dA = ∫∫ κ(r, θ) r dr dθ`` (plane polar
coordinates). For a mixture fitted in the plane, ``κ = M̂ (π₀ u + Σ_j π_j N_j)`` at
``site + r (sin θ, cos θ)``; for one fitted in range and bearing by a
:class:`~mhtrack.clutter.polar.PolarClutter` (coordinates ``(r, s = r₀ (θ − θ_cut) mod
2π)``), the plane intensity is ``κ_polar(r, s) · r₀ / max(r, r_min)``, so the integrand is
``κ_polar(r, s) · r₀ r / max(r, r_min)`` — the wrapper's ``min_range`` floor included, and
no mass at ``r < 0`` or ``s`` outside ``[0, 2π r₀)``, which the plane never sees.

Each integral is a product of 1-D Gauss–Legendre rules (Abramowitz & Stegun 25.4.29) on
segments of range and bearing: ``∫_a^b f ≈ (b − a)/2 Σ_q w_q f(m + (b − a)/2 x_q)``,
exact for polynomials of degree ``2n − 1`` on each segment, :data:`NODES` nodes each:

* a Gaussian over its ``±`` :data:`REACH_SIGMA` σ box (marginal σ along and across the
  bearing of its mean; in range and ``s`` for a polar mixture), cut at the cells' edges,
  at ``r_min`` and, along an axis where the cells are wider than :data:`STEP_SIGMA` times
  its conditional σ (in bearing: σ / range), into steps of that width — so a clump
  smaller than a cell or across an edge is integrated as finely as a broad one is by
  the cells (the 2-node rule on a step of 2σ: < 1.1 % of the step's mass);
* the background's box: the cells, cut at the box's edges in range and bearing for a
  polar mixture (exact there); in the plane, the box's indicator at the cells' nodes.

All the Gaussians of a mixture are integrated in one vectorised pass (its segments and
node products by numba's compiled loops on long runs, the same floats:
:mod:`mhtrack.clutter.cell_mass_rows`). Tested against a
60 × 60 midpoint grid per cell (tests/clutter/test_cell_mass.py): within 1 % of the
mixture's mass per cell.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.clutter import cell_mass_rows

#: Gauss–Legendre nodes per segment and axis.
NODES = 2
#: Half-width, in σ, of the box a Gaussian is integrated over (mass outside < 1e-3).
REACH_SIGMA = 3.5

#: Steps of a narrow Gaussian's box, in its conditional σ.
STEP_SIGMA = 2.0
#: Most steps of a narrow Gaussian's box per axis (bounds the cost of a thin Gaussian).
MAX_STEPS = 8

_X, _W = np.polynomial.legendre.leggauss(NODES)
TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class Cells:
    """The map's geometry and the base's coordinates: ``n_rings`` rings of ``dr`` (m) by
    ``n_azimuth`` sectors about ``site``; ``polar`` ``(r0, min_range, cut)`` of a
    :class:`~mhtrack.clutter.polar.PolarClutter` base, or ``None`` (a plane base)."""

    site: tuple[float, float]
    dr: float
    n_rings: int
    n_azimuth: int
    polar: tuple[float, float, float] | None = None

    @property
    def dtheta(self) -> float:
        return TWO_PI / self.n_azimuth


def _segments(lo: float, hi: float, step: float, cell: float, extra: tuple[float, ...] = ()
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes, weights and cell index (``⌊node / cell⌋``) of the Gauss–Legendre rule on
    ``[lo, hi]`` cut at multiples of ``cell``, at ``lo + k·step`` (at most
    :data:`MAX_STEPS` steps) and at ``extra``."""
    if not hi > lo:
        return np.zeros(0), np.zeros(0), np.zeros(0, np.int64)
    cuts = [np.array([lo, hi]), np.arange(np.floor(lo / cell) + 1, np.ceil(hi / cell)) * cell]
    step = max(step, (hi - lo) / MAX_STEPS)
    if step < hi - lo:
        cuts.append(lo + np.arange(1, np.ceil((hi - lo) / step)) * step)
    cuts.append(np.array([e for e in extra if lo < e < hi]))
    b = np.unique(np.concatenate(cuts))
    b = b[(b >= lo) & (b <= hi)]
    half, mid = 0.5 * np.diff(b), 0.5 * (b[1:] + b[:-1])
    x = (mid[:, None] + half[:, None] * _X[None, :]).reshape(-1)
    w = (half[:, None] * _W[None, :]).reshape(-1)
    idx = np.repeat(np.floor(mid / cell).astype(np.int64), NODES)
    return x, w, idx


def _grid(cells: Cells, r: tuple[np.ndarray, np.ndarray, np.ndarray],
          t: tuple[np.ndarray, np.ndarray, np.ndarray]
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Product rule of range nodes ``r`` and bearing nodes ``t``: (n, 2) points in the base's
    coordinates, weights ``w_r w_θ · r · J(r)`` (``J = r₀/max(r, r_min)`` for a polar base)
    and flat cell index (−1 beyond the map)."""
    rr, wr, ir = r
    tt, wt, it = t
    w_r = wr * rr
    if cells.polar is not None:
        r0, rmin, _ = cells.polar
        w_r = w_r * r0 / np.maximum(rr, rmin)
    ring = np.repeat(ir, len(tt))
    flat = np.where(ring < cells.n_rings, ring * cells.n_azimuth
                    + np.tile(np.mod(it, cells.n_azimuth), len(rr)), -1)
    w = np.outer(w_r, wt).reshape(-1)
    rg, tg = np.repeat(rr, len(tt)), np.tile(tt, len(rr))
    if cells.polar is not None:
        r0, _, cut = cells.polar
        pts = np.column_stack([rg, r0 * np.mod(tg - cut, TWO_PI)])
    else:
        pts = np.column_stack([cells.site[0] + rg * np.sin(tg), cells.site[1] + rg * np.cos(tg)])
    return pts, w, flat


def cell_nodes(cells: Cells) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rule of every cell (``NODES`` per axis, rings cut at ``r_min`` for a polar base):
    points in the base's coordinates, weights, flat cell index (for the plane
    background)."""
    reach = cells.n_rings * cells.dr
    extra = () if cells.polar is None else (cells.polar[1],)
    start = 0.0 if cells.polar is None else cells.polar[2]  # the polar base's cut
    r = _segments(0.0, reach, np.inf, cells.dr, extra)
    t = _segments(start, start + TWO_PI, np.inf, cells.dtheta)
    return _grid(cells, r, t)


def _pdf(pts: np.ndarray, mean: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """(n, k) Gaussian densities ``N(p_i; μ_j, Σ_j)`` (closed-form 2 × 2 inverse)."""
    det = cov[:, 0, 0] * cov[:, 1, 1] - cov[:, 0, 1] ** 2
    dx = pts[:, 0, None] - mean[None, :, 0]
    dy = pts[:, 1, None] - mean[None, :, 1]
    q = (cov[:, 1, 1] * dx * dx - 2.0 * cov[:, 0, 1] * dx * dy + cov[:, 0, 0] * dy * dy) / det
    return np.exp(-0.5 * q) / (TWO_PI * np.sqrt(det))


def _batch_segments(lo: np.ndarray, hi: np.ndarray, step: np.ndarray, extra: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_segments` of several windows at once, in units of the cell (edges at the
    integers): (J, P) nodes, weights (0 on the empty segments that pad the rows to one
    length) and cell index."""
    hi = np.maximum(hi, lo)
    step = np.maximum(step, (hi - lo) / MAX_STEPS)
    step = np.where(step < 1.0, step, np.maximum(hi - lo, 1e-300))  # the cells are finer
    first = np.floor(lo) + 1.0
    n_edge = max(0, int(np.max(np.ceil(hi) - first)))
    n_step = max(1, int(np.max(np.ceil((hi - lo) / step))))
    b = np.concatenate([lo[:, None], hi[:, None], extra[:, None],
                        first[:, None] + np.arange(n_edge),
                        lo[:, None] + np.arange(1, n_step) * step[:, None]], axis=1)
    b = np.sort(np.clip(b, lo[:, None], hi[:, None]), axis=1)
    half, mid = 0.5 * np.diff(b, axis=1), 0.5 * (b[:, 1:] + b[:, :-1])
    x = (mid[:, :, None] + half[:, :, None] * _X).reshape(len(lo), -1)
    w = (half[:, :, None] * _W).reshape(len(lo), -1)
    idx = np.repeat(np.floor(mid).astype(np.int64), NODES, axis=1)
    return x, w, idx


def _gauss_mass(cells: Cells, weights: np.ndarray, means: np.ndarray, cov: np.ndarray,
                 out: np.ndarray) -> None:
    """Add to ``out`` the Gaussians' mass per cell: the rule on each one's
    ``±REACH_SIGMA σ`` box (module docstring), all at once."""
    reach, k, n = cells.n_rings * cells.dr, REACH_SIGMA, len(weights)
    det = cov[:, 0, 0] * cov[:, 1, 1] - cov[:, 0, 1] ** 2
    if cells.polar is not None:
        r0, rmin, cut = cells.polar
        sr, ss = np.sqrt(cov[:, 0, 0]), np.sqrt(cov[:, 1, 1])
        cr, cs = np.sqrt(det / cov[:, 1, 1]), np.sqrt(det / cov[:, 0, 0])  # conditional σ
        r_lo, r_hi = np.maximum(0.0, means[:, 0] - k * sr), np.minimum(reach,
                                                                        means[:, 0] + k * sr)
        t_lo = cut + np.maximum(0.0, means[:, 1] - k * ss) / r0
        t_hi = cut + np.minimum(TWO_PI * r0, means[:, 1] + k * ss) / r0
        r_step, t_step, r_extra = cr, cs / r0, np.full(n, rmin)
    else:  # along (u) and across (v) the bearing of each mean
        d = means - np.asarray(cells.site)
        dist = np.hypot(d[:, 0], d[:, 1])
        u = np.divide(d, np.maximum(dist, 1e-9)[:, None], out=np.tile([0.0, 1.0], (n, 1)),
                      where=(dist > 0)[:, None])  # at the site: any unit vector
        c00, c01, c11 = cov[:, 0, 0], cov[:, 0, 1], cov[:, 1, 1]
        uu = u[:, 0] * u[:, 0] * c00 + 2.0 * u[:, 0] * u[:, 1] * c01 + u[:, 1] * u[:, 1] * c11
        vv = c00 + c11 - uu  # the trace is invariant
        ca, cb = np.sqrt(det / vv), np.sqrt(det / uu)  # conditional σ
        ea, eb = k * np.sqrt(uu), k * np.sqrt(vv)  # the box's half-sides
        r_lo = np.maximum(0.0, dist - ea)
        r_hi = np.minimum(reach, np.hypot(dist + ea, eb))
        away = ea < dist
        half = np.where(away, np.arctan2(eb, np.maximum(dist - ea, 1e-9)), np.pi)
        bearing = np.where(away, np.arctan2(d[:, 0], d[:, 1]), np.pi)
        t_lo, t_hi = bearing - half, bearing + half
        r_step, t_step = ca, cb / np.maximum(np.where(away, dist, r_hi), 1e-9)
        r_extra = r_lo
    unit = np.repeat([cells.dr, cells.dtheta], n)
    lo, hi = np.concatenate([r_lo, t_lo]) / unit, np.concatenate([r_hi, t_hi]) / unit
    step = STEP_SIGMA * np.concatenate([r_step, t_step]) / unit
    extra = np.concatenate([r_extra, t_lo]) / unit
    rows = cell_mass_rows.kernels()
    if rows is not None:  # the same floats, compiled (cell_mass_rows)
        x, w, idx, ok = rows["segments"](lo, hi, step, extra, unit, _X, _W, MAX_STEPS)
        if ok:
            _compiled_products(rows, cells, x, w, idx, weights, means, cov, det, out)
            return
    x, w, idx = _batch_segments(lo, hi, step, extra)
    x, w = x * unit[:, None], w * unit[:, None]
    rr, wr, ir, tt, wt, it = x[:n], w[:n], idx[:n], x[n:], w[n:], idx[n:]
    w_r = wr * rr
    if cells.polar is not None:
        w_r *= r0 / np.maximum(rr, rmin)
    # each component's range nodes (non-empty segments in the map) times its bearing nodes
    jr, pr = np.nonzero((wr > 0) & (ir < cells.n_rings))
    jt, pt = np.nonzero(wt > 0)
    nt = np.bincount(jt, minlength=n)
    reps = nt[jr]
    a = np.repeat(np.arange(len(jr)), reps)
    ends = np.cumsum(reps)
    b = np.arange(int(ends[-1]) if len(ends) else 0) + np.repeat(np.cumsum(nt)[jr] - ends,
                                                                    reps)
    comp, r_n, t_n = jr[a], rr[jr, pr][a], tt[jt, pt]
    if cells.polar is not None:
        dx = r_n - means[comp, 0]
        dy = (r0 * np.mod(t_n - cut, TWO_PI))[b] - means[comp, 1]
    else:
        dx = r_n * np.sin(t_n)[b] + (cells.site[0] - means[comp, 0])
        dy = r_n * np.cos(t_n)[b] + (cells.site[1] - means[comp, 1])
    c = (cov / det[:, None, None])[comp]
    val = np.exp(-0.5 * (c[:, 1, 1] * dx * dx - 2.0 * c[:, 0, 1] * dx * dy
                         + c[:, 0, 0] * dy * dy))
    val *= (weights / (TWO_PI * np.sqrt(det)))[comp] * w_r[jr, pr][a] * wt[jt, pt][b]
    flat = ir[jr, pr][a] * cells.n_azimuth + np.mod(it[jt, pt], cells.n_azimuth)[b]
    out += np.bincount(flat, val, minlength=out.size)


def _compiled_products(rows: dict, cells: Cells, x: np.ndarray, w: np.ndarray,
                       idx: np.ndarray, weights: np.ndarray, means: np.ndarray,
                       cov: np.ndarray, det: np.ndarray, out: np.ndarray) -> None:
    """:func:`_gauss_mass`'s node products by the compiled loop, the exponential, sines and
    cosines by NumPy (:mod:`mhtrack.clutter.cell_mass_rows`)."""
    n = len(weights)
    tt = x[n:]
    if cells.polar is not None:
        r0, rmin, cut = cells.polar
        ta, tb = r0 * np.mod(tt - cut, TWO_PI), tt
    else:
        r0, rmin = 1.0, 0.0
        ta, tb = np.sin(tt), np.cos(tt)
    arg, coef, flat = rows["products"](
        x[:n], w[:n], idx[:n], ta, tb, w[n:], idx[n:], cells.polar is not None, r0, rmin,
        float(cells.site[0]), float(cells.site[1]), weights, means, cov, det,
        cells.n_rings, cells.n_azimuth)
    val = np.exp(arg)
    val *= coef
    out += np.bincount(flat, val, minlength=out.size)


def background_mass(cells: Cells, nodes: tuple[np.ndarray, np.ndarray, np.ndarray],
                    box: tuple[float, float, float, float]) -> np.ndarray:
    """(n_rings·n_azimuth,) ``∫_c u dA`` of the background uniform on ``box`` (its
    coordinates the base's): exact for a polar base, the indicator at ``nodes`` (the
    cells' rule) in the plane."""
    x0, x1, y0, y1 = box
    area = (x1 - x0) * (y1 - y0)
    size = cells.n_rings * cells.n_azimuth
    if not area > 0:
        return np.zeros(size)
    if cells.polar is not None:
        r0, rmin, cut = cells.polar
        reach = cells.n_rings * cells.dr
        r = _segments(max(x0, 0.0), min(x1, reach), np.inf, cells.dr, (rmin,))
        t = _segments(cut + max(y0, 0.0) / r0, cut + min(y1, TWO_PI * r0) / r0, np.inf,
                      cells.dtheta)
        pts, w, flat = _grid(cells, r, t)
    else:
        pts, w, flat = nodes
        w = w * ((pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1))
    ok = flat >= 0
    return np.bincount(flat[ok], w[ok], minlength=size) / area


def mixture_mass(cells: Cells, weights: np.ndarray, means: np.ndarray, cov: np.ndarray
                 ) -> np.ndarray:
    """(n_rings·n_azimuth,) ``∫_c Σ_j π_j N_j dA`` per cell (module docstring)."""
    out = np.zeros(cells.n_rings * cells.n_azimuth)
    if not len(weights):
        return out
    weights, means, cov = (np.ascontiguousarray(a, float) for a in (weights, means, cov))
    _gauss_mass(cells, weights, means.reshape(-1, 2), cov.reshape(-1, 2, 2), out)
    return out


def preload() -> bool:
    """Load the compiled loops of the quadrature now (:func:`cell_mass_rows.load`) and
    compile them on a small mixture, in the plane and in range and bearing, rather than in
    the middle of a run; whether they are in use. The floats of later calls do not depend
    on it."""
    if not cell_mass_rows.load():
        return False
    one, mean, cov = np.ones(1), np.array([[1500.0, 1500.0]]), 1e6 * np.eye(2)[None]
    for polar in (None, (1e4, 100.0, 0.0)):
        mixture_mass(Cells((0.0, 0.0), 1000.0, 4, 8, polar), one, mean, cov)
    return True
