"""Clutter intensity from a Gaussian mixture fitted online: ``κ̂_k(z) = M̂_k ĉ_k(z)`` (P1 eq. 14).

:class:`MixtureClutter` holds everything the GMM (:mod:`mhtrack.clutter.gmm`) and the
adaptive GMM (:mod:`mhtrack.clutter.agmm`) estimators share; they differ only in the rule
that deletes components after each M-step. Every scan :meth:`MixtureClutter.update`

1. takes the scan's *feeding* plots — all of them (``source="all"``) or those outside
   confirmed tracks' gates (``source="outside-gates"``) — into a sliding window of the last
   ``window`` scans, pooled together so that a sparse scan still fits;
2. estimates the clutter count ``M̂_k`` (P1 eq. 14) by the Poisson maximum-likelihood
   estimate: the window's counts ``n_j`` are taken as independent Poisson draws of one mean
   ``λ``; their likelihood ``Π_j e^{−λ} λ^{n_j} / n_j!`` is largest at ``λ̂ = (1/W) Σ_j n_j``,
   the mean count (e.g. Casella & Berger, *Statistical Inference*, Ex. 7.2.8; P1 [4] uses
   the same ML estimate for the count in a gate);
3. fits ``ĉ_k`` (P1 eqs. 6–13) by EM (:func:`mhtrack.clutter.em.fit_em`), warm-started from
   the previous scan's fit, and
4. answers :meth:`intensity` with ``M̂_k ĉ_k(z)`` (plots per m² per scan).

See ``docs/clutter.md`` for the reasoning behind every default.
"""

from __future__ import annotations

from collections import deque
from typing import Any, Literal

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.density import PDF_DIRECT, log_pdf_t, maha_det_t, offsets_t, plots_t
from mhtrack.clutter.em import Mixture, PruneRule, fit_em
from mhtrack.clutter.seeding import ScanRngs, kmeanspp_centres, mixture_from_centres
from mhtrack.clutter.state_checks import check_mixture_estimator
from mhtrack.kernels import all_, max_, min_, same_floats, sum_
from mhtrack.models.clutter import Region
from mhtrack.records import Scan

Source = Literal["all", "outside-gates"]
SOURCES: tuple[str, ...] = ("all", "outside-gates")
#: χ²₂ 0.99 quantile: a plot farther than this (squared Mahalanobis) from every component
#: is "unexplained" and may seed a new component at the next warm start.
CHI2_2_99 = 9.2103


class MixtureClutter(ClutterEstimator):
    """Online Gaussian-mixture clutter estimator (shared base of ``gmm`` and ``agmm``).

    Parameters
    ----------
    n_components : ``K``, Gaussian components EM starts from (and refills up to at a warm
        start). Default 8: twice the four of P1 Table 2 — "more than the truth" (P1 §2).
    source : ``"all"`` plots of the scan, or ``"outside-gates"``: leave out plots inside
        confirmed tracks' gates (likely target plots; the tracker's ``in_track_gates``).
        Default ``"all"``.
    window : ``W``, scans pooled into one fit; ``M̂_k`` is their mean count. Default 5.
    background : add a uniform component over the data's box (below) so that ``κ̂`` does
        not collapse to ~0 away from the clutter clumps and stray plots (targets, uniform
        clutter) do not drag Gaussians around. Default True.
    background_floor : lower bound on the background weight ``π₀``. Default 0.01.
    region : the box of the uniform background; default ``None``: the bounding box of the
        window's plots, padded by 5 % of its extent and at least ``min_extent`` wide.
    min_extent : smallest side (m) of the data's box. Default 1000.
    reg_covar : added to every covariance diagonal (m²), as scikit-learn's ``reg_covar``
        (1e−6 there, for unit-free data); default 100 m² (σ ≥ 10 m, a tenth of P1's σw).
    tol : ``ε`` of P1's stopping rule ``|ΔL| < ε|L|``. Default 1e−4 (with ``|L|`` ≈ 10–20 per
        plot in metres, about scikit-learn's absolute 1e−3).
    max_iter : most EM iterations per scan. Default 100.
    min_points : delete components with fewer effective plots ``n_j``; 3 is the fewest that
        give a 2×2 covariance without collapsing onto a plot. Default 3.
    warm_start : start each scan's EM from the previous fit (plus new components, below);
        else from k-means++ seeds every scan. Default True.
    max_points : pooled plots above this are subsampled (without replacement, seeded)
        before EM, counted in ``n_subsampled_``; ``M̂_k`` still uses all. Default 2000.
    seed : seeds the k-means++ draws; scan ``u`` (the ``u``-th update) uses
        ``SeedSequence(seed, spawn_key=(u,))``. Default 0.
    min_contrast : with a background, delete a Gaussian whose peak ``π_j / (2π√|Σ_j|)`` is
        below ``min_contrast`` times the background's density ``π₀/A`` — a broad bump that
        fits the fluctuations of uniform clutter, not a clump. Default 5 (ours, empirical:
        half to a quarter of the weakest true clump of our scenarios, ~20 for the swollen
        patch of ``docs/examples/drifting-clutter.toml``; 0 turns it off).
    bic : with a background, also delete a Gaussian whose removal costs the fit less than
        the BIC price of its six parameters, ``3 ln n`` nats
        (:func:`~mhtrack.clutter.em.removal_gain`) — a test of the number of components,
        part of the adaptive GMM (``agmm``, default on there), not of the fixed-threshold
        GMM (``gmm``, default off). Default False here (``docs/clutter.md``).

    Warm start: the previous Gaussians are kept and, when at least ``min_points`` of the
    pooled plots are farther than χ²₂(0.99) from all of them, up to ``K − K_prev`` new
    components are seeded among those plots by k-means++ (Zivkovic 2004 likewise opens a
    component for a sample no component explains). EM then prunes what is not needed.

    Attributes (learned, updated by :meth:`update`)
    ----------------------------------------------
    mixture_ : the fitted :class:`~mhtrack.clutter.em.Mixture`, ``None`` before any plot.
    count_ : ``M̂_k``, the Poisson ML clutter count per scan.
    n_iter_, converged_, log_likelihood_, n_pruned_ : of the last EM run.
    n_updates_ : scans seen. n_subsampled_ : plots left out by ``max_points`` so far.
    """

    name = "mixture"

    def __init__(
        self,
        n_components: int = 8,
        *,
        source: Source = "all",
        window: int = 5,
        background: bool = True,
        background_floor: float = 0.01,
        region: Region | tuple[float, float, float, float] | None = None,
        min_extent: float = 1000.0,
        reg_covar: float = 100.0,
        tol: float = 1e-4,
        max_iter: int = 100,
        min_points: float = 3.0,
        warm_start: bool = True,
        max_points: int = 2000,
        seed: int = 0,
        min_contrast: float = 5.0,
        bic: bool = False,
    ) -> None:
        if not (isinstance(n_components, int | np.integer) and n_components >= 1):
            raise ValueError(f"n_components must be an integer >= 1, got {n_components!r}")
        if source not in SOURCES:
            raise ValueError(f"source must be one of {SOURCES}, got {source!r}")
        if not (isinstance(window, int | np.integer) and window >= 1):
            raise ValueError(f"window must be an integer >= 1, got {window!r}")
        for label, v in (("reg_covar", reg_covar), ("min_extent", min_extent)):
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{label} must be finite and > 0, got {v!r}")
        if not (np.isfinite(tol) and tol >= 0):
            raise ValueError(f"tol must be finite and >= 0, got {tol!r}")
        if not 0.0 <= background_floor < 1.0:
            raise ValueError(f"background_floor must be in [0, 1), got {background_floor!r}")
        if not (isinstance(max_iter, int | np.integer) and max_iter >= 1):
            raise ValueError(f"max_iter must be an integer >= 1, got {max_iter!r}")
        if not (isinstance(max_points, int | np.integer) and max_points >= 10):
            raise ValueError(f"max_points must be an integer >= 10, got {max_points!r}")
        if not (np.isfinite(min_contrast) and min_contrast >= 0):
            raise ValueError(f"min_contrast must be finite and >= 0, got {min_contrast!r}")
        if not (np.isfinite(min_points) and min_points >= 0):
            raise ValueError(f"min_points must be finite and >= 0, got {min_points!r}")
        if region is not None and not isinstance(region, Region):
            region = Region(*(float(v) for v in region))
        self.n_components = int(n_components)
        self.source = source
        self.window = int(window)
        self.background = bool(background)
        self.background_floor = float(background_floor) if background else 0.0
        self.region = region
        self.min_extent = float(min_extent)
        self.reg_covar = float(reg_covar)
        self.tol = float(tol)
        self.max_iter = int(max_iter)
        self.min_points = float(min_points)
        self.warm_start = bool(warm_start)
        self.max_points = int(max_points)
        self.seed = int(seed)
        self.min_contrast = float(min_contrast)
        self.bic = bool(bic)
        self._reset()

    def _reset(self) -> None:
        self._window: deque[np.ndarray] = deque(maxlen=self.window)
        self._kept: np.ndarray = np.zeros(0, np.int64)  # last scan's plots in the window
        self.mixture_: Mixture | None = None
        self.count_ = 0.0
        self.n_iter_ = 0
        self.converged_ = False
        self.log_likelihood_ = float("nan")
        self.n_pruned_ = 0
        self.n_updates_ = 0
        self.n_subsampled_ = 0
        #: this scan's (n, 2) fed plots and their log c under the fit (the Mixture it was
        #: computed with, so that a mixture_ set by hand is not answered from it)
        self._scan_log_c: tuple[np.ndarray, np.ndarray, Mixture] | None = None
        self._rngs = ScanRngs()  # the scans' generators, made a few scans ahead

    # ------------------------------------------------------------------ what subclasses set
    def _prune_rule(self) -> PruneRule | None:
        """The component-deletion rule applied after each M-step (none here)."""
        return None

    # ------------------------------------------------------------------ ClutterEstimator
    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        """Take scan ``k``'s plots and refit ``M̂_k`` and ``ĉ_k`` (see the module docstring).

        Raises ``ValueError`` for non-finite plots or a mask of the wrong shape.
        """
        z = np.asarray(scan.z, dtype=float).reshape(-1, 2)
        if not all_(np.isfinite(z), axis=None):
            raise ValueError(f"scan {scan.index}: plots must be finite")
        if in_track_gates is not None:
            mask = np.asarray(in_track_gates, dtype=bool).reshape(-1)
            if mask.shape != (len(z),):
                raise ValueError(
                    f"scan {scan.index}: in_track_gates has {mask.size} entries, "
                    f"expected {len(z)}"
                )
        kept = np.arange(len(z))
        if in_track_gates is not None and self.source == "outside-gates":
            kept = kept[~mask]
            z = z[kept]
        self._scan_log_c = None
        rng = _LazyRng(self._rngs, self.seed, self.n_updates_)
        self.n_updates_ += 1
        self._window.append(z.copy())
        self._kept = kept
        # Poisson ML: the mean count (integer sum, exact as np.mean's float sum)
        self.count_ = float(sum(map(len, self._window))) / len(self._window)
        pooled = np.concatenate(self._window) if len(self._window) > 1 else self._window[0]
        if len(pooled) == 0:
            self.mixture_ = None
            self.n_iter_, self.converged_, self.n_pruned_ = 0, True, 0
            self.log_likelihood_ = float("nan")
            return
        subsampled = len(pooled) > self.max_points
        if subsampled:
            keep = np.sort(rng().choice(len(pooled), self.max_points, replace=False))
            self.n_subsampled_ += len(pooled) - self.max_points
            pooled = pooled[keep]
        box = self._box(pooled)
        init, glp = self._warm_init(pooled, box, rng) if self.warm_start else (None, None)
        if init is None:
            init = self._cold_init(pooled, box, rng())
        res = fit_em(
            pooled, init, reg_covar=self.reg_covar, tol=self.tol, max_iter=self.max_iter,
            prune=self._prune_rule(), min_points=self.min_points,
            background_floor=self.background_floor, min_contrast=self.min_contrast,
            bic=self.bic, init_log_pdf=glp,
        )
        self.mixture_ = res.mixture
        if not subsampled and len(z) and res.log_density is not None:
            # the scan's plots are the last rows of the pool: their log c, for intensity()
            self._scan_log_c = (self._window[-1], res.log_density[len(pooled) - len(z):],
                                res.mixture)
        self.n_iter_, self.converged_ = res.n_iter, res.converged
        self.log_likelihood_, self.n_pruned_ = res.log_likelihood, res.n_pruned

    def intensity(self, z: np.ndarray) -> np.ndarray:
        """``κ̂_k(z) = M̂_k ĉ_k(z)`` (P1 eq. 14), plots per m² per scan, at (n, 2) ``z``;
        0 before any plot was seen. Always finite and ≥ 0."""
        z = np.asarray(z, dtype=float).reshape(-1, 2)
        m, cached = self.mixture_, self._scan_log_c  # cached: with a fit, finite plots, M̂ > 0
        if (cached is not None and m is cached[2] and same_floats(cached[0], z)
                and len(z) * max(m.n_components, 1) <= PDF_DIRECT):
            # the scan's own plots: M̂ · m.pdf(z) = M̂ · exp(m.log_pdf(z)), log c from the fit
            return self.count_ * np.exp(cached[1])
        if not all_(np.isfinite(z), axis=None):
            raise ValueError("intensity: positions must be finite")
        if m is None or self.count_ == 0.0:
            return np.zeros(len(z))
        return self.count_ * m.pdf(z)

    def forget(self, used: np.ndarray) -> None:
        """Take out of the window the plots of the last scan that the tracker's best
        hypothesis gives to confirmed tracks (``used``, a mask over that scan's plots).

        Those plots are the targets', not clutter: left in, the plots of targets that fly
        together (a formation, two aircraft in trail) pile up in the window into a
        Gaussian that the next fits take for a clutter clump, and the tracks there lose
        their scores. A track uses at most one plot per scan, so a clutter clump that a
        track crosses keeps its other plots. The fit of the scan itself already happened
        (it needs ``κ̂`` before the tracker can decide); the next scans' fits and counts
        ``M̂`` go without them.
        """
        used = np.asarray(used, dtype=bool).reshape(-1)
        if not self._window or not used.any():
            return
        drop = used[self._kept] if self._kept.size else np.zeros(0, bool)
        if drop.any():
            self._window[-1] = self._window[-1][~drop]
            self._kept = self._kept[~drop]

    def density(self, z: np.ndarray) -> np.ndarray:
        """``ĉ_k(z)`` (P1 eq. 13), per m²; 0 before any plot was seen."""
        z = np.asarray(z, dtype=float).reshape(-1, 2)
        return np.zeros(len(z)) if self.mixture_ is None else self.mixture_.pdf(z)

    def get_state(self) -> dict[str, Any]:
        """The learned state (window, fit, counters) as JSON-able values and arrays."""
        return {
            "window": [w.copy() for w in self._window],
            "kept": self._kept.copy(),
            "mixture": None if self.mixture_ is None else self.mixture_.to_state(),
            "count": self.count_,
            "n_iter": self.n_iter_,
            "converged": self.converged_,
            "log_likelihood": None if np.isnan(self.log_likelihood_) else self.log_likelihood_,
            "n_pruned": self.n_pruned_,
            "n_updates": self.n_updates_,
            "n_subsampled": self.n_subsampled_,
        }

    def set_state(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`get_state` returned (parameters are the constructor's),
        checked first (:mod:`mhtrack.clutter.state_checks`)."""
        check_mixture_estimator(state)
        self._reset()
        for w in state["window"]:
            self._window.append(np.asarray(w, dtype=float).reshape(-1, 2))
        self._kept = np.asarray(state.get("kept", np.zeros(0)), np.int64).reshape(-1)
        m = state["mixture"]
        self.mixture_ = None if m is None else Mixture.from_state(m)
        self.count_ = float(state["count"])
        self.n_iter_ = int(state["n_iter"])
        self.converged_ = bool(state["converged"])
        ll = state["log_likelihood"]
        self.log_likelihood_ = float("nan") if ll is None else float(ll)
        self.n_pruned_ = int(state["n_pruned"])
        self.n_updates_ = int(state["n_updates"])
        self.n_subsampled_ = int(state["n_subsampled"])

    # ------------------------------------------------------------------ helpers
    def _box(self, z: np.ndarray) -> tuple[float, float, float, float] | None:
        """Support of the uniform background (``None`` without one)."""
        if not self.background:
            return None
        if self.region is not None:
            return self.region.as_tuple()
        # per column (the same extremes as axis=0), then per axis the same IEEE double
        # operations on Python floats that (2,) arrays would do
        x, y = z[:, 0], z[:, 1]
        box: list[float] = []
        for lo, hi in ((float(min_(x)), float(max_(x))), (float(min_(y)), float(max_(y)))):
            mid, half = 0.5 * (lo + hi), max(0.5 * (hi - lo) * 1.1, 0.5 * self.min_extent)
            box += (mid - half, mid + half)
        return (box[0], box[1], box[2], box[3])

    def _start_weight(self) -> float:
        return max(self.background_floor, 0.05) if self.background else 0.0

    def _cold_init(
        self, z: np.ndarray, box: tuple[float, float, float, float] | None,
        rng: np.random.Generator,
    ) -> Mixture:
        """k-means++ seeds among the plots, one hard assignment and M-step."""
        centres = kmeanspp_centres(z, self.n_components, rng)
        return mixture_from_centres(z, centres, reg_covar=self.reg_covar, background_box=box,
                                    background_weight=self._start_weight())

    def _warm_init(
        self, z: np.ndarray, box: tuple[float, float, float, float] | None,
        rng: _LazyRng,
    ) -> tuple[Mixture | None, np.ndarray | None]:
        """Previous Gaussians + new ones seeded among unexplained plots (``None``: cold),
        with the (K, n) log-densities of its Gaussians at ``z`` (for :func:`fit_em`)."""
        prev = self.mixture_
        if prev is None or prev.n_components == 0:
            return None, None
        bg = max(prev.background_weight, self._start_weight()) if self.background else 0.0
        w = prev.weights * (1.0 - bg) / sum_(prev.weights)
        means, cov = prev.means, prev.covariances
        z_t = plots_t(z)
        maha, det = maha_det_t(*offsets_t(z_t, means), cov)
        glp = log_pdf_t(maha, det)
        free = self.n_components - prev.n_components
        if free > 0:
            far = (min_(maha, axis=0) > CHI2_2_99).nonzero()[0]
            if len(far) >= max(self.min_points, 1.0):
                novel = z.take(far, axis=0)
                centres = kmeanspp_centres(novel, free, rng(), existing=means)
                if len(centres):
                    new = mixture_from_centres(novel, centres, reg_covar=self.reg_covar)
                    share = float(novel.shape[0]) / len(z)  # novel plots' share
                    w = np.concatenate((w * (1.0 - share), new.weights * share * (1.0 - bg)))
                    means = np.concatenate((means, new.means))
                    cov = np.concatenate((cov, new.covariances))
                    glp = np.concatenate((glp, log_pdf_t(*maha_det_t(
                        *offsets_t(z_t, new.means), new.covariances))))
        return Mixture(w, means, cov, bg, box), glp


class _LazyRng:
    """The scan's generator ``default_rng(SeedSequence(seed, spawn_key=(u,)))``, taken from
    ``rngs`` on first call (some scans draw nothing) and the same one after."""

    def __init__(self, rngs: ScanRngs, seed: int, u: int) -> None:
        self._from, self._key = rngs, (seed, u)
        self._rng: np.random.Generator | None = None

    def __call__(self) -> np.random.Generator:
        if self._rng is None:
            self._rng = self._from.take(*self._key)
        return self._rng
