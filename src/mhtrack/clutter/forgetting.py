"""A Gaussian mixture with exponential forgetting, split and merge: ``κ̂_k(z) = M̂_k ĉ_k(z)``
for clutter that drifts, swells, splits and fades.

The mixture ``ĉ(z) = π₀ u(z) + Σ_j π_j N(z; μ_j, Σ_j)`` (P1 eq. 6 with our uniform
background) is held as each component's *sufficient statistics*, discounted by ``γ_k``
at scan (rotation) ``k``: with ``r_ij`` the responsibility of component ``j`` for plot ``i``
of scan ``k`` and ``d = z − a_j`` about the component's anchor,

    M_j,pq ← γ M_j,pq + Σ_i r_ij dx^p dy^q      (p + q ≤ 4),      B ← γ B + Σ_i r_i0,
    π_j = M_j,00 / (Σ_l M_l,00 + B),    μ_j = a_j + M_j,1 / M_j,00,
    Σ_j = M_j,2 / M_j,00 − (μ_j − a_j)(μ_j − a_j)ᵀ + reg·I

— the online EM of Neal & Hinton ("A view of the EM algorithm that justifies incremental,
sparse, and other variants", 1998, §5: statistics decayed exponentially for changing
data) and Cappé & Moulines ("On-line expectation–maximization algorithm for latent data
models", JRSS B 71(3), 2009) with step ``1 − γ``: ``γ_k = forgetting`` per scan, or, with
a half-life ``h`` (``half_life``), ``2^(−Δt_k/h)`` per second of data time (``Δt_k`` since
the previous scan). The default is per scan: measured (docs/clutter.md), the memory
the mixture needs is a number of scans' plots, not of seconds (10 s suits 4–6 s
rotations; on 1 s scans it raises the clutter error by two thirds). Each scan runs EM
on its own plots only: the E-step on the new plots under the current parameters, the
M-step from the discounted past statistics plus the new ones, until ``|ΔL| < tol·|L|``:
memory and time per scan are O(K) and O(n K), whatever the history. With ``γ = 1`` and
all data in one scan it is batch EM (P1 eqs. 9–11).

After each scan, as the cells drift:

* *prune*: a component with fewer than ``min_points`` discounted plots, or whose peak is
  below ``min_contrast`` times the background's density, gives its mass to the background;
* *merge* and *split* (:mod:`mhtrack.clutter.split_merge`): two Gaussians closer than
  ``merge_distance`` (Mahalanobis) are one, their statistics added; one whose
  principal-axis kurtosis is below ``split_kurtosis`` becomes two;
* *birth*: plots beyond χ²₂(0.99) of every Gaussian (at least ``min_points``) seed new
  components by k-means++, taking their background mass (as the GMM's warm start).

As the GMM's warm start, each scan's EM starts with ``π₀ ≥ 0.05``, and a fresh start
gives the background half the plots, so that broad Gaussians do not swallow uniform
clutter before the contrast test can see them.

The count is the discounted Poisson ML ``M̂_k = C_k / N_k``, ``C ← γ_k C + n_k``,
``N ← γ_k N + 1`` (the window mean of :mod:`mhtrack.clutter.mixture` with forgetting).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.density import (
    Mixture,
    log_pdf_t,
    logsumexp_rows,
    maha_det_t,
    mahalanobis2,
    offsets_t,
    plots_t,
    responsibilities_t,
    weighted_t,
)
from mhtrack.clutter.discount import check_discount, discount
from mhtrack.clutter.moments import I00, mean_cov, plot_moments
from mhtrack.clutter.seeding import kmeanspp_centres
from mhtrack.clutter.split_merge import merge, reanchor, split
from mhtrack.models.clutter import Region
from mhtrack.records import Scan

CHI2_2_99 = 9.2103
#: Each scan's EM starts with ``π₀`` at least this (the GMM's warm start does the same).
START_WEIGHT = 0.05
#: ``γ`` per scan (rotation) of the statistics (measured: docs/clutter.md).
FORGETTING = 0.7


class ForgettingGMMClutter(ClutterEstimator):
    """Forgetting Gaussian mixture with split and merge (module docstring).

    Parameters
    ----------
    forgetting : ``γ`` in (0, 1] per scan (memory ``1/(1 − γ)`` scans). Default
        :data:`FORGETTING` unless ``half_life`` is given.
    half_life : ``h`` (s of data time, ``inf``: no forgetting): the statistics are
        discounted by ``γ_k = 2^(−Δt_k/h)`` instead (:mod:`mhtrack.clutter.discount`; not
        with ``forgetting``). Default ``None``.
    n_components : most Gaussians. Default 8.
    background : a uniform component over ``region`` or the box of the plots seen so far
        (padded 5 %, at least ``min_extent`` wide). Default True.
    background_floor : lowest ``π₀``. Default 0.01.
    region : the background's box; default: the plots' box.
    reg_covar, tol, max_iter, min_points, min_contrast, min_extent : as the GMM's
        (:class:`~mhtrack.clutter.mixture.MixtureClutter`); defaults 100 m², 1e−4, 20, 3,
        5, 1000 m.
    merge_distance : Mahalanobis distance under which two Gaussians merge. Default 1.
    split_kurtosis : principal-axis kurtosis under which a Gaussian splits (0: never).
        Default 2.
    seed : seeds the k-means++ draws of scan ``u``: ``SeedSequence(seed, spawn_key=(u,))``.
    """

    name = "fgmm"

    def __init__(self, *, forgetting: float | None = None, half_life: float | None = None,
                 n_components: int = 8,
                 background: bool = True, background_floor: float = 0.01,
                 region: Region | tuple[float, float, float, float] | None = None,
                 reg_covar: float = 100.0, tol: float = 1e-4, max_iter: int = 20,
                 min_points: float = 3.0, min_contrast: float = 5.0,
                 min_extent: float = 1000.0, merge_distance: float = 1.0,
                 split_kurtosis: float = 2.0, seed: int = 0) -> None:
        check_discount(forgetting, half_life)
        if forgetting is None and half_life is None:
            forgetting = FORGETTING
        if not (isinstance(n_components, int | np.integer) and 1 <= n_components <= 256):
            raise ValueError(f"n_components must be an integer in [1, 256], got "
                             f"{n_components!r}")
        if not (isinstance(max_iter, int | np.integer) and max_iter >= 1):
            raise ValueError(f"max_iter must be an integer >= 1, got {max_iter!r}")
        if not 0.0 <= background_floor < 1.0:
            raise ValueError(f"background_floor must be in [0, 1), got {background_floor!r}")
        for label, v in (("reg_covar", reg_covar), ("min_extent", min_extent)):
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{label} must be finite and > 0, got {v!r}")
        for label, v in (("tol", tol), ("min_points", min_points),
                         ("min_contrast", min_contrast), ("merge_distance", merge_distance)):
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"{label} must be finite and >= 0, got {v!r}")
        if not (np.isfinite(split_kurtosis) and 0.0 <= split_kurtosis < 3.0):
            raise ValueError(f"split_kurtosis must be in [0, 3), got {split_kurtosis!r}")
        if region is not None and not isinstance(region, Region):
            region = Region(*(float(v) for v in region))
        self.forgetting = None if forgetting is None else float(forgetting)
        self.half_life = None if half_life is None else float(half_life)
        self.n_components = int(n_components)
        self.background = bool(background)
        self.background_floor = float(background_floor) if background else 0.0
        self.region = region
        self.reg_covar, self.tol, self.max_iter = float(reg_covar), float(tol), int(max_iter)
        self.min_points, self.min_contrast = float(min_points), float(min_contrast)
        self.min_extent = float(min_extent)
        self.merge_distance, self.split_kurtosis = float(merge_distance), float(split_kurtosis)
        self.seed = int(seed)
        self.moments_ = np.zeros((0, 15))  # (K, 15) about anchors_
        self.anchors_ = np.zeros((0, 2))
        self.bg_mass_ = 0.0
        self.count_sum_, self.looks_ = 0.0, 0.0
        self.box_: tuple[float, float, float, float] | None = None
        self.extent_: tuple[float, float, float, float] | None = None  # plots seen, unpadded
        self.n_updates_ = 0
        self.time_: float | None = None  # the last scan's time
        self.mixture_: Mixture | None = None
        #: the mixture the last scan's EM started from
        self.start_: Mixture | None = None
        self._last_z = None  # the last scan's plots, for forget

    # ------------------------------------------------------------------ the mixture
    def _box(self, z: np.ndarray) -> tuple[float, float, float, float] | None:
        """The background's box: ``region``, else the box of every plot seen so far
        (``extent_``), padded by 5 % and to at least ``min_extent``."""
        if not self.background:
            return None
        if self.region is not None:
            r = self.region
            return (r.xmin, r.xmax, r.ymin, r.ymax)
        lo, hi = z.min(axis=0), z.max(axis=0)
        if self.extent_ is not None:
            lo = np.minimum(lo, [self.extent_[0], self.extent_[2]])
            hi = np.maximum(hi, [self.extent_[1], self.extent_[3]])
        self.extent_ = (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
        return self._padded()

    def _padded(self) -> tuple[float, float, float, float] | None:
        if self.extent_ is None:
            return None
        x0, x1, y0, y1 = self.extent_
        lo, hi = np.array([x0, y0]), np.array([x1, y1])
        pad = np.maximum(0.05 * (hi - lo), 0.5 * np.maximum(self.min_extent - (hi - lo), 0))
        return (float(lo[0] - pad[0]), float(hi[0] + pad[0]), float(lo[1] - pad[1]),
                float(hi[1] + pad[1]))

    def _mixture(self, m: np.ndarray, bg: float, floor: float = 0.0) -> Mixture:
        """The mixture of statistics ``m`` and background mass ``bg`` (``π₀`` at least
        ``background_floor`` and ``floor``)."""
        w, means, cov = mean_cov(m, self.anchors_, self.reg_covar)
        total = w.sum() + bg
        if self.box_ is None:
            return Mixture(w / w.sum(), means, cov)
        w0 = max(bg / total, self.background_floor, floor) if total > 0 else 1.0
        gw = w.sum()
        return Mixture(w * (1.0 - w0) / gw if gw > 0 else w, means, cov, w0, self.box_)

    # ------------------------------------------------------------------ one scan
    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        """Decay, EM on the scan's plots, then prune, merge, split and birth (module
        docstring). ``ValueError`` for non-finite plots."""
        z = np.asarray(scan.z, float).reshape(-1, 2)
        if not np.isfinite(z).all():
            raise ValueError(f"scan {scan.index}: plots must be finite")
        g = self._discount(float(scan.time))
        self.count_sum_ = g * self.count_sum_ + len(z)
        self.looks_ = g * self.looks_ + 1.0
        self.moments_ = self.moments_ * g
        self.bg_mass_ *= g
        rng = np.random.default_rng(np.random.SeedSequence(self.seed,
                                                           spawn_key=(self.n_updates_,)))
        self.n_updates_ += 1
        self._last_z: np.ndarray | None = z
        if len(z) == 0:
            self._finish()
            return
        self.box_ = self._box(z)
        past, past_bg = self.moments_, self.bg_mass_
        new, new_bg, prev = np.zeros_like(past), 0.0, -np.inf
        if len(past) == 0:  # a fresh start: k-means++ seeds, a hard E-step, this scan only
            self._birth(z, np.ones(len(z)), rng, first=True)
            past, new = np.zeros_like(self.moments_), self.moments_
            if not len(new):
                self._finish()
                return
            if self.box_ is not None:  # the background starts with half the plots
                new, new_bg = 0.5 * new, 0.5 * len(z)
        self.start_ = self._mixture(past + new, past_bg + new_bg, START_WEIGHT)
        z_t = plots_t(z)
        with np.errstate(divide="ignore"):
            log_bg = self.start_.log_background(z)
            for it in range(self.max_iter):  # E-step (P1 eq. 9) on this scan's plots
                mix = (self.start_ if it == 0 else
                       self._mixture(past + new, past_bg + new_bg))
                maha, det = maha_det_t(*offsets_t(z_t, mix.means), mix.covariances)
                wlp = weighted_t(mix.background_weight, mix.weights, log_pdf_t(maha, det),
                                 log_bg)
                norm, resp = responsibilities_t(wlp)  # (K+1, n), row 0 the background
                ll = float(norm.mean())
                new = plot_moments(z, self.anchors_, resp[1:], order=2)  # M-step's sums
                new_bg = float(resp[0].sum())
                if abs(ll - prev) < self.tol * abs(prev):
                    break
                prev = ll
        new = plot_moments(z, self.anchors_, resp[1:])  # all orders, the last E-step
        self.moments_, self.bg_mass_ = past + new, past_bg + new_bg
        self._reanchor()
        self._prune()
        if self.merge_distance > 0:
            self.moments_, self.anchors_ = merge(self.moments_, self.anchors_,
                                                 self.reg_covar, self.merge_distance)
        self.moments_, self.anchors_ = split(self.moments_, self.anchors_,
                                             self.n_components - len(self.moments_),
                                             self.min_points, self.split_kurtosis)
        if len(self.moments_):
            mix = self._mixture(self.moments_, self.bg_mass_)
            d2 = mahalanobis2(z, mix.means, mix.covariances).min(axis=1)
            far = d2 > CHI2_2_99
            if np.count_nonzero(far) >= max(self.min_points, 1):
                wlp = mix.weighted_log_prob(z[far])
                self._birth(z[far], np.exp(wlp[:, 0] - logsumexp_rows(wlp)), rng)
            if len(self.moments_) == mix.n_components:  # no birth: the mixture is at hand
                self.mixture_ = mix
                return
        else:
            self._birth(z, np.ones(len(z)), rng)
        self._finish()

    def _discount(self, t: float) -> float:
        """``γ_k`` (:func:`mhtrack.clutter.discount.discount`)."""
        last, self.time_ = self.time_, t
        return discount(last, t, forgetting=self.forgetting, half_life=self.half_life)

    def _finish(self) -> None:
        self.mixture_ = (None if len(self.moments_) == 0 and self.box_ is None
                         else self._mixture(self.moments_, self.bg_mass_)
                         if len(self.moments_) else Mixture(np.zeros(0), np.zeros((0, 2)),
                                                            np.zeros((0, 2, 2)), 1.0,
                                                            self.box_))

    def _reanchor(self) -> None:
        self.moments_, self.anchors_ = reanchor(self.moments_, self.anchors_)

    def _drop(self, keep: np.ndarray) -> None:
        self.bg_mass_ += float(self.moments_[~keep, I00].sum()) if self.background else 0.0
        self.moments_, self.anchors_ = self.moments_[keep], self.anchors_[keep]

    def _prune(self) -> None:
        w = self.moments_[:, I00]
        keep = w >= max(self.min_points, 1e-9)
        if self.min_contrast > 0 and self.box_ is not None and keep.any():
            mix = self._mixture(self.moments_, self.bg_mass_)
            peak = mix.weights / (2 * np.pi * np.sqrt(np.linalg.det(mix.covariances)))
            keep &= peak >= self.min_contrast * mix.background_weight / mix.background_area
        if not keep.all():
            self._drop(keep)

    def _birth(self, z: np.ndarray, mass: np.ndarray, rng: np.random.Generator,
               first: bool = False) -> None:
        room = self.n_components - len(self.moments_)
        if room <= 0 or len(z) < max(self.min_points, 1):
            return
        centres = kmeanspp_centres(z, room, rng)
        lab = ((z[:, None, :] - centres[None]) ** 2).sum(axis=2).argmin(axis=1)
        resp = (lab[None, :] == np.arange(len(centres))[:, None]) * mass[None, :]
        ok = resp.sum(axis=1) >= max(self.min_points, 1e-9)
        if not ok.any():
            return
        m = plot_moments(z, centres[ok], resp[ok])
        self.moments_ = np.vstack([self.moments_, m])
        self.anchors_ = np.vstack([self.anchors_, centres[ok]])
        if not first:
            self.bg_mass_ = max(self.bg_mass_ - float(m[:, I00].sum()), 0.0)
        self._reanchor()

    # ------------------------------------------------------------------ ClutterEstimator
    def forget(self, used: np.ndarray) -> None:
        """Take the last scan's plots that confirmed tracks used (``used``, a mask over
        them) out of the count and of the statistics, with their responsibilities under
        the current mixture; a Gaussian left with no weight or a degenerate covariance
        goes back to the background."""
        z = self._last_z
        used = np.asarray(used, bool).reshape(-1)
        if z is None or used.shape != (len(z),) or not used.any():
            return
        zu = z[used]
        self.count_sum_ = max(self.count_sum_ - len(zu), 0.0)
        if self.mixture_ is not None and len(self.moments_):
            wlp = self.mixture_.weighted_log_prob(zu)
            resp = np.exp(wlp - logsumexp_rows(wlp)[:, None])
            self.moments_ = self.moments_ - plot_moments(zu, self.anchors_, resp[:, 1:].T)
            self.bg_mass_ = max(self.bg_mass_ - float(resp[:, 0].sum()), 0.0)
            w, _, cov = mean_cov(self.moments_, self.anchors_, 0.0)
            ok = (w > 1e-9) & (cov[:, 0, 0] > 0) & (np.linalg.det(cov) > 0)
            if not ok.all():
                self.moments_[~ok, I00] = np.maximum(self.moments_[~ok, I00], 0.0)
                self._drop(ok)
            self._finish()
        self._last_z = None

    @property
    def count_(self) -> float:
        """``M̂_k = C_k / N_k``."""
        return self.count_sum_ / self.looks_ if self.looks_ > 0 else 0.0

    def intensity(self, z: np.ndarray) -> np.ndarray:
        """``κ̂(z) = M̂_k ĉ_k(z)`` per m² per scan; 0 before any plot."""
        z = np.asarray(z, float).reshape(-1, 2)
        if not np.isfinite(z).all():
            raise ValueError("intensity: positions must be finite")
        if self.mixture_ is None or self.count_ == 0.0:
            return np.zeros(len(z))
        return self.count_ * self.mixture_.pdf(z)

    def get_state(self) -> dict[str, Any]:
        return {"moments": self.moments_.copy(), "anchors": self.anchors_.copy(),
                "bg_mass": float(self.bg_mass_), "count_sum": float(self.count_sum_),
                "looks": float(self.looks_), "n_updates": int(self.n_updates_),
                "time": self.time_,
                "box": None if self.box_ is None else list(self.box_),
                "extent": None if self.extent_ is None else list(self.extent_),
                "last_z": np.zeros((0, 2)) if self._last_z is None else self._last_z.copy()}

    def set_state(self, state: dict[str, Any]) -> None:
        from mhtrack.bounds import MAX_TIME_S
        from mhtrack.clutter.state_checks import MAX_COORDINATE, array, check_forgetting, number

        m, a, box, extent = check_forgetting(
            state, self.n_components, self.forgetting or 1.0)
        self.moments_, self.anchors_, self.box_, self.extent_ = m, a, box, extent
        self.bg_mass_ = float(state["bg_mass"])
        self.count_sum_, self.looks_ = float(state["count_sum"]), float(state["looks"])
        self.n_updates_ = int(state["n_updates"])
        self.time_ = None if state.get("time") is None else float(
            number(state["time"], "clutter_state.time", -MAX_TIME_S, MAX_TIME_S))
        last = array(state["last_z"], "clutter_state.last_z", (-1, 2), bound=MAX_COORDINATE)
        self._last_z = np.asarray(last, float) if len(last) else None
        self._finish()
