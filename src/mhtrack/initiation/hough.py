"""Hough-transform track initiation, plain and modified (P2 §3.2; P2 refs. [2], [6]).

All plots of a window of ``N`` scans (P2: 4) vote in a ``(θ, ρ)`` accumulator, where the
line through a plot ``(x, y)`` at normal angle ``θ`` has ``ρ = x cos θ + y sin θ``,
coordinates taken relative to an origin ``c`` (P2 gives neither origin nor ``ρ`` range;
ours: the surveillance region's centre when ``region`` is given — the CLI gives the
scenario's — else the centre of the window's plots' bounding box):

* ``θ`` in ``N_θ`` cells over ``[0, π)`` (P2: 90, i.e. 2° each), evaluated at the cell
  centres ``θ_j = (j + ½) π / N_θ``;
* ``ρ`` in ``N_ρ`` cells over ``[−ρ_max, ρ_max]`` (P2: 90), ``ρ_max`` the region's
  half-diagonal, or without a region the largest distance of a window plot from ``c``
  (plots outside the region vote in the edge cells);
* a cell's vote count is the number of **distinct scans** with a plot in it (several plots
  of one scan give one vote: a track has one plot per scan); a cell with ``≥ votes``
  (P2: 4, so with ``N = 4`` every scan) is a detected line.

Plain Hough: each detected cell gives one track, made of the plot of each voting scan
nearest to the cell's line (``|ρ_i − ρ_cell|`` smallest). Modified Hough (P2 §3.2: "speed,
acceleration and angle" constraints): each detected cell gives every sequence of its plots,
one per scan (at most ``N − votes`` scans without one), that satisfies, over its
consecutive plots ``z_a → z_b`` (times ``t_a < t_b``):

* velocity: ``v_min ≤ ‖z_b − z_a‖ / (t_b − t_a) ≤ v_max`` (ours: 50, 400 m/s; ``t`` the
  plot's scan time, or its own time when the window has one, :attr:`Window.t`);
* acceleration (``accel_max`` given; P2 §3.2 names the constraint without a formula or
  a value): the speeds of consecutive legs ``v₁ = ‖z_q − z_p‖/(t_q − t_p)``,
  ``v₂ = ‖z − z_q‖/(t − t_q)`` change by ``|v₂ − v₁| ≤ a_max · (t − t_p)/2`` (the time
  between the legs' midpoints; the scalar form of the modified Hough of P2 refs. [2], [6]);
  off by default (``None``); ``reproduce p2 --tracker-settings paper`` uses
  ``a_max = 150`` m/s² (ours: on ``multiradar`` the speed of a leg between fused plots is
  noisy — cross-range σ = 0.3° × range — and 150 keeps p_true within 0.02 of no
  constraint while halving the false tracks; 30 would keep p_true at 0.15);
* time order (``time_order=True``): the positions along the line,
  ``u = −x sin θ + y cos θ``, are strictly monotonic in time (the target moves one way);
* angle: consecutive legs turn by ``α ≤ θ_max`` (as the modified logic; P2: 20°).

The sequences are grown scan by scan inside each cell, dropping a prefix as soon as it
fails a test. Tracks found in several cells are kept once, and a track whose plots are
all in another is dropped. The initial state is the least-squares line fit of
:mod:`mhtrack.initiation.window`. Everything is array work over (plot, θ) votes.
"""

from __future__ import annotations

import numpy as np

from mhtrack.initiation.base import Initiator, check_window_and_speeds
from mhtrack.initiation.window import NO_PLOT, Window, last_slot, previous_plot


class HoughInitiator(Initiator):
    """Hough-transform initiation, plain or modified (module docstring).

    Parameters
    ----------
    modified : add the velocity, acceleration (if ``accel_max``), time-order (if
        ``time_order``) and angle constraints.
    n_theta, n_rho : accumulator size (P2: 90 × 90).
    votes : detection threshold in distinct scans (P2: 4).
    angle_limit_deg : ``θ_max`` of the modified transform (P2's θ: 20°).
    v_min, v_max : velocity constraint (m/s) of the modified transform (ours: 50, 400).
    accel_max : acceleration constraint ``a_max`` (m/s²) of the modified transform, or
        ``None`` (off; P2 gives no value).
    time_order : the time-order constraint of the modified transform (on).
    n_scans : ``N`` (P2: 4).
    region : ``(xmin, xmax, ymin, ymax)`` of the surveillance region fixing the
        accumulator's origin and ``ρ`` range (ours); ``None``: from each window's plots.
    """

    def __init__(self, *, modified: bool = False, n_theta: int = 90, n_rho: int = 90,
                 votes: int = 4, angle_limit_deg: float = 20.0, v_min: float = 50.0,
                 v_max: float = 400.0, n_scans: int = 4,
                 region: tuple[float, float, float, float] | None = None,
                 accel_max: float | None = None, time_order: bool = True) -> None:
        self.modified = modified
        self.accel_max = accel_max
        self.time_order = time_order
        self.n_theta = n_theta
        self.n_rho = n_rho
        self.votes = votes
        self.angle_limit_deg = angle_limit_deg
        self.v_min = v_min
        self.v_max = v_max
        self.n_scans = n_scans
        self.region = region

    def check_parameters(self) -> None:
        """The accumulator, window and constraint parameters (``ValueError`` naming the
        bad one)."""
        check_window_and_speeds(self.n_scans, max(2, min(self.votes, self.n_scans)),
                                self.v_min, self.v_max)
        for name in ("n_theta", "n_rho"):
            v = getattr(self, name)
            if not (isinstance(v, int) and v >= 1):
                raise ValueError(f"{name} must be an integer >= 1, got {v!r}")
        if not (isinstance(self.votes, int) and 2 <= self.votes <= self.n_scans):
            raise ValueError(f"votes must be an integer in [2, n_scans], got {self.votes!r}")
        if self.region is not None:
            x0, x1, y0, y1 = (float(v) for v in self.region)
            if not (x0 < x1 and y0 < y1):
                raise ValueError(f"region must be (xmin, xmax, ymin, ymax), got {self.region}")
        if not 0 <= self.angle_limit_deg <= 180:
            raise ValueError(f"angle_limit_deg must be in [0, 180], got {self.angle_limit_deg}")
        a = self.accel_max
        if a is not None and not (isinstance(a, int | float) and a > 0):
            raise ValueError(f"accel_max must be > 0 or None, got {a!r}")

    # ------------------------------------------------------------------ accumulator
    def accumulate(self, w: Window) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Votes of the window: ``(votes (N_θ, N_ρ), theta (N_θ,), rho_edges (N_ρ+1,),
        centre (2,))``; ``votes[j, b]`` = number of distinct scans with a plot in cell
        ``(j, b)``."""
        self.check_parameters()
        cell, _, theta, edges, centre = self._cells(w)
        counts = self._distinct_votes(cell, w.slot)
        return counts.reshape(self.n_theta, self.n_rho), theta, edges, centre

    def _cells(self, w: Window) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                          np.ndarray]:
        """Cell index (n, N_θ) and ρ (n, N_θ) of every (plot, θ) vote."""
        theta = (np.arange(self.n_theta) + 0.5) * np.pi / self.n_theta
        if len(w) == 0:
            e = np.zeros((0, self.n_theta))
            return e.astype(np.int64), e, theta, np.linspace(-1, 1, self.n_rho + 1), \
                np.zeros(2)
        if self.region is not None:
            x0, x1, y0, y1 = (float(v) for v in self.region)
            centre = np.array([0.5 * (x0 + x1), 0.5 * (y0 + y1)])
            rho_max = 0.5 * float(np.hypot(x1 - x0, y1 - y0))
            xy = w.z - centre
        else:
            centre = 0.5 * (w.z.min(axis=0) + w.z.max(axis=0))
            xy = w.z - centre
            rho_max = max(float(np.hypot(xy[:, 0], xy[:, 1]).max()), 1e-6)
        rho = xy[:, :1] * np.cos(theta) + xy[:, 1:] * np.sin(theta)  # (n, N_θ)
        b = np.floor((rho + rho_max) / (2 * rho_max) * self.n_rho).astype(np.int64)
        b = np.clip(b, 0, self.n_rho - 1)
        cell = np.arange(self.n_theta) * self.n_rho + b
        edges = np.linspace(-rho_max, rho_max, self.n_rho + 1)
        return cell, rho, theta, edges, centre

    def _distinct_votes(self, cell: np.ndarray, slot: np.ndarray) -> np.ndarray:
        n_cells = self.n_theta * self.n_rho
        seen = np.zeros(n_cells * self.n_scans, bool)
        seen[(cell * self.n_scans + slot[:, None]).ravel()] = True
        return seen.reshape(n_cells, self.n_scans).sum(axis=1)

    # ------------------------------------------------------------------ tracks
    def find_tracks(self, w: Window) -> np.ndarray:
        """Plain: per detected cell, its plot nearest the line at each voting scan;
        modified: every constrained plot sequence per cell (module docstring)."""
        N = self.n_scans
        empty = np.full((0, N), NO_PLOT, np.int64)
        if len(w) == 0:
            return empty
        cell, rho, theta, edges, _ = self._cells(w)
        counts = self._distinct_votes(cell, w.slot)
        hit = counts[cell] >= self.votes  # (n, N_θ) votes that fall in detected cells
        if not hit.any():
            return empty
        plot, j = np.nonzero(hit)
        c = cell[plot, j]
        s = w.slot[plot]
        gid = c * N + s  # (cell, scan) group of each vote
        present = np.zeros(self.n_theta * self.n_rho, bool)
        present[c] = True
        cells = np.flatnonzero(present)
        remap = np.cumsum(present) - 1
        if not self.modified:
            # per (cell, scan): the plot nearest to the cell's line |ρ − ρ_cell|
            centre_rho = 0.5 * (edges[:-1] + edges[1:])[c % self.n_rho]
            off = np.abs(rho[plot, j] - centre_rho)
            best = np.full(len(present) * N, np.inf)
            np.minimum.at(best, gid, off)
            win = off == best[gid]
            chosen = np.full(len(present) * N, NO_PLOT, np.int64)
            chosen[gid[win]] = plot[win]
            g = np.flatnonzero(chosen >= 0)
            flat = np.full((len(cells), N), NO_PLOT, np.int64)
            flat[remap[g // N], g % N] = chosen[g]
            return flat
        # group by (cell, scan): a stable sort (radix sort when the key fits 16 bits)
        key = gid.astype(np.uint16) if len(present) * N <= 1 << 16 else gid
        o = np.argsort(key, kind="stable")
        return self._constrained_sequences(w, plot[o], remap[c[o]], s[o],
                                           theta[cells // self.n_rho])

    def _constrained_sequences(self, w: Window, plot: np.ndarray, cell_of: np.ndarray,
                               s: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """Modified transform: per detected cell, the plot sequences (one plot per scan,
        at most ``N − votes`` scans without one) passing the velocity, time-order and
        angle tests, grown scan by scan so that failing prefixes are dropped early.
        ``plot, cell_of, s`` are the votes in detected cells sorted by (cell, scan)."""
        N = self.n_scans
        n_cells = len(theta)
        cnt = np.zeros((n_cells, N), np.int64)
        np.add.at(cnt, (cell_of, s), 1)
        off = (np.cumsum(cnt.ravel()) - cnt.ravel()).reshape(n_cells, N)
        max_miss = N - self.votes
        z, tp = w.z, w.plot_times()  # each plot's time (its scan's, or its own)
        dirs = np.column_stack((-np.sin(theta), np.cos(theta)))  # along-line unit vectors
        path = np.full((0, N), NO_PLOT, np.int64)
        g = np.zeros(0, np.int64)  # cell of each partial sequence
        cos_lim = np.cos(np.radians(self.angle_limit_deg))
        for c in range(N):  # loop over the N scans of the window
            if len(path):
                hits = (path >= 0).sum(axis=1)
                last = path[np.arange(len(path)), last_slot(path)]
                prev = previous_plot(path)
                k = cnt[g, c]
                q = np.repeat(np.arange(len(path)), k)
                j = plot[np.repeat(off[g, c] - np.cumsum(k) + k, k) + np.arange(int(k.sum()))]
                # velocity: v_min·Δt ≤ ‖leg‖ ≤ v_max·Δt
                leg = z[j] - z[last[q]]
                dt = tp[j] - tp[last[q]]
                d2 = leg[:, 0] ** 2 + leg[:, 1] ** 2
                ok = (d2 >= (self.v_min * dt) ** 2) & (d2 <= (self.v_max * dt) ** 2)
                q, j, leg, d2, dt = q[ok], j[ok], leg[ok], d2[ok], dt[ok]
                # time order: the along-line motion keeps its (non-zero) sign
                u = (leg * dirs[g[q]]).sum(axis=1)
                two = hits[q] >= 2
                pleg = z[last[q]] - z[np.maximum(prev[q], 0)]
                pu = (pleg * dirs[g[q]]).sum(axis=1)
                ok = (u != 0) & (~two | (np.sign(u) == np.sign(pu)))
                if not self.time_order:
                    ok = np.ones(len(q), bool)
                if self.accel_max is not None:
                    # acceleration: |v₂ − v₁| ≤ a_max · (t − t_p)/2
                    dt1 = tp[last[q]] - tp[np.maximum(prev[q], 0)]
                    with np.errstate(divide="ignore", invalid="ignore"):
                        v1 = np.hypot(pleg[:, 0], pleg[:, 1]) / dt1
                    dv = np.abs(np.sqrt(d2) / dt - v1)
                    ok &= ~two | (dv <= self.accel_max * 0.5 * (dt + dt1))
                # angle: cos α = leg·pleg / (‖leg‖ ‖pleg‖) ≥ cos θ_max
                dot = (leg * pleg).sum(axis=1)
                norm = np.sqrt(d2 * (pleg[:, 0] ** 2 + pleg[:, 1] ** 2))
                ok &= ~two | ((norm > 0) & (dot >= cos_lim * norm))
                q, j = q[ok], j[ok]
                ext = path[q].copy()
                ext[:, c] = j
                may_miss = (c - hits + 1) <= max_miss
                path, g = np.concatenate((ext, path[may_miss])), np.concatenate(
                    (g[q], g[may_miss]))
            if c <= max_miss:
                k = cnt[:, c]
                born = np.full((int(k.sum()), N), NO_PLOT, np.int64)
                born[:, c] = plot[np.repeat(off[:, c] - np.cumsum(k) + k, k)
                                  + np.arange(int(k.sum()))]
                path = np.concatenate((path, born))
                g = np.concatenate((g, np.repeat(np.arange(n_cells), k)))
        return path[(path >= 0).sum(axis=1) >= self.votes]


