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
exact for polynomials of degree ``2n − 1`` on each segment. The segments are

* for a Gaussian the cells resolve (its conditional σ along range and across bearing at
  least :data:`RESOLVED` times the cell's sides at its mean): each cell, split at
  ``r_min``, with :data:`NODES` nodes per axis (the cells' nodes are made once per map);
* for a narrower one: its ``±`` :data:`REACH_SIGMA` σ box, cut at the cells' edges and
  into steps of :data:`STEP_SIGMA` conditional σ (in bearing: σ / range), with
  :data:`NODES` nodes per step — a clump smaller than a cell or across an edge, which a
  rule per cell would miss;
* the background's box: the cells, cut at the box's edges in range and bearing for a
  polar mixture (exact there); in the plane, the box's indicator at the cells' nodes.

Tested against a 60 × 60 midpoint grid per cell (tests/clutter/test_cell_mass.py): within
1 % of the mixture's mass per cell.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Gauss–Legendre nodes per segment and axis.
NODES = 2
#: A Gaussian is integrated per cell when its conditional σ along each axis of the cell is
#: at least this times the cell's side (2-node rule's error < 0.1 % of a cell's mass).
RESOLVED = 1.0
#: Half-width, in σ, of the box a narrow Gaussian is integrated over (mass outside < 1e-4).
REACH_SIGMA = 4.0

#: Steps of a narrow Gaussian's box, in its conditional σ.
STEP_SIGMA = 2.0
#: Most steps of a narrow Gaussian's box per axis (bounds the cost of a thin Gaussian).
MAX_STEPS = 12

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
    points in the base's coordinates, weights, flat cell index."""
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


def _batch_segments(lo: np.ndarray, hi: np.ndarray, step: np.ndarray, cell: float,
                    extra: float | None = None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_segments` of several windows at once: (J, P) nodes, weights (0 on the
    empty segments that pad the rows to one length) and cell index."""
    lo, hi = np.asarray(lo, float), np.minimum(np.asarray(hi, float), np.inf)
    hi = np.maximum(hi, lo)
    step = np.maximum(step, (hi - lo) / MAX_STEPS)
    first = np.floor(lo / cell) + 1.0
    n_edge = int(max(0.0, float(np.max(np.ceil(hi / cell) - first)))) if len(lo) else 0
    n_step = int(np.max(np.ceil((hi - lo) / step))) if len(lo) else 0
    parts = [lo[:, None], hi[:, None], (first[:, None] + np.arange(n_edge)) * cell,
             lo[:, None] + np.arange(1, max(n_step, 1)) * step[:, None]]
    if extra is not None:
        parts.append(np.full((len(lo), 1), extra))
    b = np.sort(np.clip(np.concatenate(parts, axis=1), lo[:, None], hi[:, None]), axis=1)
    half, mid = 0.5 * np.diff(b, axis=1), 0.5 * (b[:, 1:] + b[:, :-1])
    x = (mid[:, :, None] + half[:, :, None] * _X).reshape(len(lo), -1)
    w = (half[:, :, None] * _W).reshape(len(lo), -1)
    idx = np.repeat(np.floor(mid / cell).astype(np.int64), NODES, axis=1)
    return x, w, idx


def _narrow_mass(cells: Cells, weights: np.ndarray, means: np.ndarray, cov: np.ndarray,
                 out: np.ndarray) -> None:
    """Add to ``out`` the narrow Gaussians' mass per cell: the rule on each one's
    ``±REACH_SIGMA σ`` box (module docstring), all at once."""
    reach, k = cells.n_rings * cells.dr, REACH_SIGMA
    det = cov[:, 0, 0] * cov[:, 1, 1] - cov[:, 0, 1] ** 2
    if cells.polar is not None:
        r0, rmin, cut = cells.polar
        sr, ss = np.sqrt(cov[:, 0, 0]), np.sqrt(cov[:, 1, 1])
        cr, cs = np.sqrt(det / cov[:, 1, 1]), np.sqrt(det / cov[:, 0, 0])  # conditional σ
        rr, wr, ir = _batch_segments(np.maximum(0.0, means[:, 0] - k * sr),
                                     np.minimum(reach, means[:, 0] + k * sr),
                                     STEP_SIGMA * cr, cells.dr, rmin)
        s_lo = np.maximum(0.0, means[:, 1] - k * ss)
        s_hi = np.minimum(TWO_PI * r0, means[:, 1] + k * ss)
        tt, wt, it = _batch_segments(cut + s_lo / r0, cut + s_hi / r0, STEP_SIGMA * cs / r0,
                                     cells.dtheta)
    else:
        d = means - np.asarray(cells.site)
        dist = np.hypot(d[:, 0], d[:, 1])
        ev = np.linalg.eigvalsh(cov)
        smin, smax = np.sqrt(np.maximum(ev[:, 0], 1e-300)), np.sqrt(ev[:, 1])
        r_hi = np.minimum(reach, dist + k * smax)
        rr, wr, ir = _batch_segments(np.maximum(0.0, dist - k * smax), r_hi,
                                     STEP_SIGMA * smin, cells.dr)
        away = k * smax < dist
        half = np.where(away, np.arcsin(np.minimum(k * smax / np.maximum(dist, 1e-300), 1.0)),
                        np.pi)
        bearing = np.where(away, np.arctan2(d[:, 0], d[:, 1]), np.pi)
        tt, wt, it = _batch_segments(bearing - half, bearing + half, STEP_SIGMA * smin
                                     / np.maximum(np.where(away, dist, r_hi), 1e-9),
                                     cells.dtheta)
    j, pr, pt = len(weights), rr.shape[1], tt.shape[1]
    w_r = wr * rr
    if cells.polar is not None:
        w_r = w_r * r0 / np.maximum(rr, rmin)
    rg = np.broadcast_to(rr[:, :, None], (j, pr, pt))
    tg = np.broadcast_to(tt[:, None, :], (j, pr, pt))
    if cells.polar is not None:
        px, py = rg, r0 * np.mod(tg - cut, TWO_PI)
    else:
        px, py = cells.site[0] + rg * np.sin(tg), cells.site[1] + rg * np.cos(tg)
    dx, dy = px - means[:, 0, None, None], py - means[:, 1, None, None]
    c = cov[:, :, :, None, None]
    q = (c[:, 1, 1] * dx * dx - 2.0 * c[:, 0, 1] * dx * dy + c[:, 0, 0] * dy * dy) \
        / det[:, None, None]
    val = (np.exp(-0.5 * q) * (weights / (TWO_PI * np.sqrt(det)))[:, None, None]
           * w_r[:, :, None] * wt[:, None, :])
    ring = np.broadcast_to(ir[:, :, None], (j, pr, pt))
    flat = ring * cells.n_azimuth + np.mod(np.broadcast_to(it[:, None, :], (j, pr, pt)),
                                           cells.n_azimuth)
    ok = (ring < cells.n_rings) & (val > 0)
    out += np.bincount(flat[ok], val[ok], minlength=out.size)


def resolved(cells: Cells, means: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """(K,) whether each Gaussian's conditional σ along range and across bearing is at
    least :data:`RESOLVED` times the cell's sides at its mean."""
    det = cov[:, 0, 0] * cov[:, 1, 1] - cov[:, 0, 1] ** 2
    if cells.polar is not None:
        r0 = cells.polar[0]
        ca, cb = np.sqrt(det / cov[:, 1, 1]), np.sqrt(det / cov[:, 0, 0])
        return (ca >= RESOLVED * cells.dr) & (cb >= RESOLVED * r0 * cells.dtheta)
    d = means - np.asarray(cells.site)
    dist = np.hypot(d[:, 0], d[:, 1])
    u = d / np.maximum(dist, 1e-9)[:, None]
    v = np.column_stack([-u[:, 1], u[:, 0]])
    # conditional σ along a unit vector a: 1 / sqrt(aᵀ Σ⁻¹ a) = sqrt(det / bᵀ Σ b), b ⊥ a
    ca = np.sqrt(det / np.einsum("ki,kij,kj->k", v, cov, v))
    cb = np.sqrt(det / np.einsum("ki,kij,kj->k", u, cov, u))
    side_b = np.maximum(dist, 0.5 * cells.dr) * cells.dtheta
    return (ca >= RESOLVED * cells.dr) & (cb >= RESOLVED * side_b)


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


def mixture_mass(cells: Cells, nodes: tuple[np.ndarray, np.ndarray, np.ndarray],
                 weights: np.ndarray, means: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """(n_rings·n_azimuth,) ``∫_c Σ_j π_j N_j dA`` per cell (module docstring); ``nodes``
    :func:`cell_nodes` of ``cells``."""
    size = cells.n_rings * cells.n_azimuth
    out = np.zeros(size)
    if not len(weights):
        return out
    res = resolved(cells, means, cov)
    if res.any():
        pts, w, flat = nodes
        ok = flat >= 0
        val = _pdf(pts[ok], means[res], cov[res]) @ weights[res]
        out += np.bincount(flat[ok], val * w[ok], minlength=size)
    if not res.all():
        low = ~res
        _narrow_mass(cells, weights[low], means[low], cov[low], out)
    return out
