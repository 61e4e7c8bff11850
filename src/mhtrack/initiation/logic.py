"""M/N logic track initiation and P2's modified logic with an angle constraint (P2 §2.1).

Over a window of ``N`` scans (P2: 4) a track is started when plots at ``≥ M`` of them
(P2: 3) line up (the "3/4 logic", P2 ref. [1]). As implemented, scan by scan (slots
``0 … N−1`` of the window, times ``t_s``):

* **start**: every plot of a slot ``s ≤ N − M`` opens a partial track (its earlier slots
  are misses);
* **second plot** (velocity gate): a partial track with one plot ``z_a`` takes every plot
  ``z`` of the next slot with ``v_min ≤ ‖z − z_a‖ / (t − t_a) ≤ v_max``;
* **later plots** (position gate): with its last two plots ``z_p, z_q`` the track predicts
  ``ẑ = z_q + (z_q − z_p)(t − t_q)/(t_q − t_p)`` and takes every plot with ``‖z − ẑ‖ ≤ r``
  (P2: ``r = 300 m``, the same radius whatever the number of missed scans);
* **modified logic** (P2 §2.1, after Su & Wang, P2 ref. [7]): a later plot is taken only
  if the angle between the new leg ``z − z_q`` and the previous leg ``z_q − z_p`` is
  ``α ≤ θ`` (P2: ``θ = 20°``), ``cos α = (z − z_q)·(z_q − z_p) / (‖z − z_q‖ ‖z_q − z_p‖)``;
  this rejects V-shaped tracks;
* a partial track branches on **every** plot in its gate; it records a miss only when its
  gate is empty, and is dropped after more than ``N − M`` misses;
* at the end, tracks with ``≥ M`` plots are initiated, except duplicates and tracks whose
  plots are all in another initiated track (:func:`~mhtrack.initiation.window.remove_dominated`).

``v_min = 50``, ``v_max = 400`` m/s are our defaults for P2's 200 m/s targets (P2 gives
none). Every step works on arrays of partial tracks; candidates come from a k-d tree ball
query on the slot's plots. The initial state is the least-squares line fit of
:mod:`mhtrack.initiation.window`.
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import chain
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from scipy.spatial import cKDTree

from mhtrack.initiation.base import Initiator, check_window_and_speeds
from mhtrack.initiation.window import (
    NO_PLOT,
    Window,
    last_slot,
    previous_plot,
    remove_dominated,
)
from mhtrack.models.linalg2 import inv2


def leg_angle(new: np.ndarray, prev: np.ndarray) -> np.ndarray:
    """Angle (rad, in ``[0, π]``) between leg vectors ``new`` and ``prev`` (…, 2):
    ``α = arccos(new·prev / (‖new‖ ‖prev‖))``; ``π`` when a leg has zero length."""
    dot = (new * prev).sum(-1)
    nn = np.hypot(new[..., 0], new[..., 1]) * np.hypot(prev[..., 0], prev[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(nn > 0, dot / nn, -1.0)
    return np.arccos(np.clip(c, -1.0, 1.0))


def _ball(tree: cKDTree, centres: np.ndarray, radius: np.ndarray | float,
          ) -> tuple[np.ndarray, np.ndarray]:
    """(query row, hit) pairs of a ball query, flattened."""
    if len(centres) == 0 or tree.n == 0:
        e = np.zeros(0, np.int64)
        return e, e
    hits = tree.query_ball_point(centres, radius)
    counts = np.fromiter((len(h) for h in hits), np.int64, count=len(hits))
    q = np.repeat(np.arange(len(hits), dtype=np.int64), counts)
    j = np.fromiter(chain.from_iterable(hits), np.int64, count=int(counts.sum()))
    return q, j


#: Above this many (centre, plot) pairs :func:`_candidates` builds a k-d tree.
BRUTE_PAIRS = 1 << 16


def _candidates(pts: np.ndarray, centres: np.ndarray, radius: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """(centre, plot) pairs with ``‖pts[j] − centres[q]‖ ≤ radius[q]`` (a superset: the
    radius is widened by a relative 1e-12 so that rounding never drops a pair), sorted
    by ``q`` then ``j``. The callers apply their exact gate to these pairs, so this is a
    prefilter only: all pairs at once for the few plots of a timed slot, a k-d tree ball
    query beyond :data:`BRUTE_PAIRS` pairs."""
    r = radius * (1.0 + 1e-12) + 1e-9
    if len(centres) * len(pts) > BRUTE_PAIRS:
        from scipy.spatial import cKDTree
        return _ball(cKDTree(pts), centres, r)
    dx = pts[None, :, 0] - centres[:, None, 0]
    dy = pts[None, :, 1] - centres[:, None, 1]
    q, j = np.nonzero(np.hypot(dx, dy) <= r[:, None])
    return q, j


def _second_timed(tp: np.ndarray, z: np.ndarray, rows: np.ndarray,
                  last: np.ndarray, v_min: float, v_max: float
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Velocity gate of the second plot with each plot at its own time ``tp``: the pairs
    ``(query row, slot row)`` with ``v_min·Δt ≤ ‖z − z_a‖ ≤ v_max·Δt``, ``Δt > 0``."""
    dt_max = np.maximum(tp[rows].max() - tp[last], 0.0)
    q, j = _candidates(z[rows], z[last], v_max * dt_max)
    dt = tp[rows[j]] - tp[last[q]]
    d = np.hypot(*(z[rows[j]] - z[last[q]]).T)
    ok = (dt > 0) & (d >= v_min * dt) & (d <= v_max * dt)
    return q[ok], j[ok]


def _lmax(R: np.ndarray) -> np.ndarray:
    """Largest eigenvalue of 2×2 symmetric matrices (…, 2, 2)."""
    h = 0.5 * (R[..., 0, 0] + R[..., 1, 1])
    d = 0.5 * (R[..., 0, 0] - R[..., 1, 1])
    return h + np.hypot(d, R[..., 0, 1])


def _later_timed(w: Window, rows: np.ndarray, a: np.ndarray, b: np.ndarray,
                 gate_radius: float, gate_chi2: float | None
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Position gate of a later plot with each plot at its own time (``w.t``): the
    straight line through ``z_a, z_b`` predicts ``ẑ = z_b + (z_b − z_a)(t − t_b)/(t_b − t_a)``
    at the plot's time ``t``; the plot is taken when ``‖z − ẑ‖ ≤ r`` or, with ``gate_chi2``
    ``γ``, ``νᵀS⁻¹ν ≤ γ`` with the prediction's covariance
    ``S = (1 + s)² R_b + s² R_a + R``, ``s = (t − t_b)/(t_b − t_a)`` (the three plots'
    errors, independent). Returns ``(query row, slot row)`` pairs."""
    tp, z = w.t, w.z
    assert tp is not None
    ta, tb = tp[a], tp[b]
    span = tb - ta
    vel = (z[b] - z[a]) / span[:, None]
    tlo, thi = float(tp[rows].min()), float(tp[rows].max())
    centre = z[b] + vel * (0.5 * (tlo + thi) - tb)[:, None]
    radius = np.full(len(a), float(gate_radius))
    if gate_chi2 is not None:
        s_hi = (thi - tb) / span
        bound = ((1 + s_hi) ** 2 * _lmax(w.R[b]) + s_hi**2 * _lmax(w.R[a])
                 + float(_lmax(w.R[rows]).max()))
        radius = np.maximum(radius, np.sqrt(gate_chi2 * bound))
    radius = radius + np.hypot(vel[:, 0], vel[:, 1]) * 0.5 * (thi - tlo)
    q, j = _candidates(z[rows], centre, radius)
    if len(q) == 0:
        return q, j
    aq, bq, jr = a[q], b[q], rows[j]
    s = (tp[jr] - tb[q]) / span[q]
    nu = z[jr] - (z[bq] + (z[bq] - z[aq]) * s[:, None])
    ok = np.hypot(nu[:, 0], nu[:, 1]) <= gate_radius
    if gate_chi2 is not None:
        S = ((1 + s)[:, None, None] ** 2 * w.R[bq] + (s**2)[:, None, None] * w.R[aq]
             + w.R[jr])
        d2 = np.einsum("ka,kab,kb->k", nu, inv2(S), nu)
        ok |= d2 <= gate_chi2
    return q[ok], j[ok]


class LogicInitiator(Initiator):
    """M/N logic initiation, plain (P2's 3/4 logic) or modified with the angle constraint
    ``α ≤ θ`` (P2 §2.1) — see the module docstring.

    Parameters
    ----------
    angle_limit_deg : ``θ`` in degrees for the modified logic (P2: 20); ``None`` = plain.
    gate_radius : ``r`` (m) of the position gate (P2: 300).
    v_min, v_max : velocity gate (m/s) of the second plot (ours: 50, 400).
    n_scans, min_plots : ``N`` and ``M`` (P2: 4 and 3).
    gate_chi2 : with plots at their own times (timed plots, :attr:`Window.t`), also take a
        later plot inside the χ² gate ``γ`` of the prediction's covariance (ours: a far
        radar's cross-range σ exceeds ``r``; :func:`_later_timed`); ``None``: P2's radius only.
    """

    def __init__(self, *, angle_limit_deg: float | None = None, gate_radius: float = 300.0,
                 v_min: float = 50.0, v_max: float = 400.0, n_scans: int = 4,
                 min_plots: int = 3, gate_chi2: float | None = None) -> None:
        self.gate_chi2 = gate_chi2
        self.angle_limit_deg = angle_limit_deg
        self.gate_radius = gate_radius
        self.v_min = v_min
        self.v_max = v_max
        self.n_scans = n_scans
        self.min_plots = min_plots

    def check_parameters(self) -> None:
        """The window, gate and angle parameters (``ValueError`` naming the bad one)."""
        check_window_and_speeds(self.n_scans, self.min_plots, self.v_min, self.v_max)
        if not self.gate_radius > 0:
            raise ValueError(f"gate_radius must be > 0, got {self.gate_radius!r}")
        a = self.angle_limit_deg
        if a is not None and not 0 <= a <= 180:
            raise ValueError(f"angle_limit_deg must be in [0, 180] or None, got {a!r}")
        g = self.gate_chi2
        if g is not None and not g > 0:
            raise ValueError(f"gate_chi2 must be > 0 or None, got {g!r}")

    def find_tracks(self, w: Window) -> np.ndarray:
        """The window's tracks at this initiator's angle limit (θ = π, no limit, for the
        plain logic: a leg angle is never above π)."""
        theta = np.pi if self.angle_limit_deg is None else np.radians(self.angle_limit_deg)
        path, lo, hi = branch_tracks(w, np.array([theta]), gate_radius=self.gate_radius,
                                     v_min=self.v_min, v_max=self.v_max,
                                     n_scans=self.n_scans, min_plots=self.min_plots,
                                     gate_chi2=self.gate_chi2)
        return path[(lo <= theta) & (theta < hi)]


def branch_tracks(window: Window, thetas: np.ndarray, *, gate_radius: float = 300.0,
                  v_min: float = 50.0, v_max: float = 400.0, n_scans: int = 4,
                  min_plots: int = 3, gate_chi2: float | None = None,
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The M-of-N branching of the (modified) logic over a window, for a grid of angle
    limits ``thetas`` (radians) at once.

    Scan by scan every partial track branches on each plot in its gate — the velocity gate
    ``v_min·Δt ≤ |Δz| ≤ v_max·Δt`` for the second plot, the radius ``gate_radius`` around
    the straight-line prediction after that — and takes a miss only when its gate is empty
    (at most ``n_scans − min_plots`` misses). Each partial track carries the interval
    ``lo ≤ θ < hi`` of angle limits for which it exists: taking a plot at leg angle ``α``
    needs ``θ ≥ α`` (``lo = max(lo, α)``); a miss happens only when the gate holds no plot
    with ``α ≤ θ`` (``hi = min(hi, min α)``). Partial tracks valid for no ``θ`` of the grid
    are dropped. Returns the tracks with at least ``min_plots`` plots as ``path`` (n,
    n_scans) flat plot indices (``-1`` a miss) and their intervals ``lo``, ``hi``; the
    tracks of limit ``θ`` are ``path[(lo <= θ) & (θ < hi)]``, in the initiator's order.
    """
    ths = np.sort(np.asarray(thetas, float))
    N, M = n_scans, min_plots
    max_miss = N - M
    z, t, tp = window.z, window.times, window.t

    def on_grid(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        i = np.searchsorted(ths, lo, side="left")
        return (i < len(ths)) & (ths[np.minimum(i, len(ths) - 1)] < hi)

    path = np.full((0, N), NO_PLOT, np.int64)
    lo = np.zeros(0)
    hi = np.zeros(0)
    for c in range(N):
        rows = window.rows(c)
        if len(path):
            last = path[np.arange(len(path)), last_slot(path)]
            prev = previous_plot(path)
            hits = (path >= 0).sum(axis=1)
            miss = c - hits  # slots 0..c−1 are decided: each a plot or a miss
            tree = None
            if len(rows) and tp is None:  # P2's scans; the timed gates need no tree
                from scipy.spatial import cKDTree
                tree = cKDTree(z[rows])
            q_all, j_all, a_all = [], [], []
            one = np.flatnonzero(hits == 1)
            if len(one) and len(rows) and tp is not None:
                q, j = _second_timed(tp, z, rows, last[one], v_min, v_max)
                q_all.append(one[q])
                j_all.append(rows[j])
                a_all.append(np.full(len(q), -np.inf))  # no angle test
            elif len(one) and tree is not None:
                dt = t[c] - t[window.slot[last[one]]]
                q, j = _ball(tree, z[last[one]], v_max * dt)
                d = np.hypot(*(z[rows[j]] - z[last[one[q]]]).T)
                ok = d >= v_min * dt[q]
                q_all.append(one[q[ok]])
                j_all.append(rows[j[ok]])
                a_all.append(np.full(int(ok.sum()), -np.inf))  # no angle test
            more = np.flatnonzero(hits >= 2)
            if len(more) and len(rows):
                a, b = prev[more], last[more]
                leg = z[b] - z[a]
                if tp is not None:
                    q, j = _later_timed(window, rows, a, b, gate_radius, gate_chi2)
                else:
                    assert tree is not None
                    step = (t[c] - t[window.slot[b]]) / (t[window.slot[b]] - t[window.slot[a]])
                    pred = z[b] + leg * step[:, None]
                    q, j = _ball(tree, pred, gate_radius)
                ang = (leg_angle(z[rows[j]] - z[b[q]], leg[q]) if len(q)
                       else np.zeros(0))
                q_all.append(more[q])
                j_all.append(rows[j])
                a_all.append(ang)
            q = np.concatenate(q_all) if q_all else np.zeros(0, np.int64)
            j = np.concatenate(j_all) if j_all else np.zeros(0, np.int64)
            ang = np.concatenate(a_all) if a_all else np.zeros(0)
            gate_min = np.full(len(path), np.inf)
            np.minimum.at(gate_min, q, ang)
            ext_lo = np.maximum(lo[q], ang)
            ext_hi = hi[q]
            ok = on_grid(ext_lo, ext_hi)
            extended = path[q[ok]].copy()
            extended[:, c] = j[ok]
            mis_hi = np.minimum(hi, gate_min)
            mis = (miss + 1 <= max_miss) & on_grid(lo, mis_hi)
            path = np.concatenate((extended, path[mis]))
            lo = np.concatenate((ext_lo[ok], lo[mis]))
            hi = np.concatenate((ext_hi[ok], mis_hi[mis]))
        if c <= max_miss and len(rows):
            born = np.full((len(rows), N), NO_PLOT, np.int64)
            born[:, c] = rows
            path = np.concatenate((path, born))
            lo = np.concatenate((lo, np.full(len(rows), -np.inf)))
            hi = np.concatenate((hi, np.full(len(rows), np.inf)))
    full = (path >= 0).sum(axis=1) >= M
    return path[full], lo[full], hi[full]


def sweep_modified_logic(window: Window, thetas_deg: Sequence[float], *,
                         gate_radius: float = 300.0, v_min: float = 50.0,
                         v_max: float = 400.0, n_scans: int = 4, min_plots: int = 3,
                         ) -> list[np.ndarray]:
    """The tracks (flat plot indices, as ``InitiatedTracks.flat``) that
    ``make_initiator("modified-logic", theta_deg=θ)`` initiates in ``window``, for every
    ``θ`` of ``thetas_deg``, from one :func:`branch_tracks` pass, each with
    :func:`~mhtrack.initiation.window.remove_dominated` applied. Not simply "the angle
    filters the plain logic's tracks": a miss branch exists only while the gate is empty,
    and a longer track removes its sub-tracks, so the track count need not be monotone
    in ``θ``."""
    th = np.radians(np.asarray(thetas_deg, float))
    path, lo, hi = branch_tracks(window, th, gate_radius=gate_radius, v_min=v_min,
                                 v_max=v_max, n_scans=n_scans, min_plots=min_plots)
    out = []
    for x in th:
        f = path[(lo <= x) & (x < hi)]
        out.append(f[remove_dominated(f)] if len(f) else f)
    return out
