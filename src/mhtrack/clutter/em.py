"""EM for a 2-D Gaussian mixture with an optional uniform background (P1 eqs. 6–11).

The mixture density of a plot ``z`` is

    c(z) = π₀ u(z) + Σ_{j=1..K} π_j N(z; μ_j, Σ_j),      π₀ + Σ π_j = 1,       (P1 eq. 6)

where ``u(z) = 1/A`` on an axis-aligned box of area ``A`` (0 outside) is an optional
uniform *background* component with a learned weight ``π₀`` (our addition; with
``background_box=None`` the model is P1's plain GMM and ``π₀ = 0``).

One EM iteration, as in scikit-learn's ``GaussianMixture`` (``sklearn/mixture/
_gaussian_mixture.py``), with optional sample weights ``s_i``:

* E-step (P1 eq. 9): ``log r_ij = log π_j + log f_j(z_i) − logsumexp_j(log π_j + log f_j(z_i))``
  (log-sum-exp responsibilities, never a ratio of tiny densities);
* M-step (P1 eqs. 10–11): ``n_j = Σ_i s_i r_ij``, ``π_j = n_j / Σ_j n_j``,
  ``μ_j = Σ_i s_i r_ij z_i / n_j``, ``Σ_j = Σ_i s_i r_ij (z_i − μ_j)(z_i − μ_j)ᵀ / n_j + reg·I``
  (``reg_covar`` as in scikit-learn); the background's ``u`` is fixed, only ``π₀`` is learned,
  constrained to ``π₀ ≥ background_floor`` (the constrained maximiser of ``Σ n_j log π_j``);
* optionally a *pruning* rule after the M-step (P1 step c: eq. 12 for the AGMM, a fixed
  weight threshold for the GMM), deletion of components with fewer than ``min_points``
  effective plots (``n_j``), which could only collapse onto a plot or two, and of
  components whose peak density is under ``min_contrast`` times the background's, and
  (``bic``) of components that do not pay for their parameters in likelihood
  (:func:`removal_gain`);
* stop when ``|L_i − L_{i−1}| < tol·|L_{i−1}|`` (P1 step 3) with no component deleted in the
  iteration, or after ``max_iter`` iterations.

``L`` is the (sample-weighted) mean log-likelihood ``(1/Σs) Σ_i s_i log c(z_i)`` — the
objective of P1 eq. 7, which EM never decreases — rather than P1's ``Q`` (eq. 10): at the
E-step they differ by the entropy of the responsibilities, and ``L`` is what scikit-learn
monitors (and returns from ``score``), so the two codes can be checked against each other.
All 2×2 arithmetic is closed-form (:mod:`mhtrack.models.linalg2`) on whole arrays, held
component-major (:mod:`mhtrack.clutter.density`: the layout, and why the floats are those
of the plain plot-major formulas).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from mhtrack.clutter.density import (
    Mixture,
    _lse_t,
    gaussian_log_pdf,
    log_pdf_t,
    logsumexp_rows,
    maha_det_t,
    mahalanobis2,
    offsets_t,
    plot_sums,
    plots_t,
    responsibilities_t,
    weighted_t,
)
from mhtrack.kernels import any_, mean, sum_
from mhtrack.models.linalg2 import sym_mahalanobis2

__all__ = ["EMResult", "Mixture", "PruneRule", "e_step", "fit_em", "gaussian_log_pdf",
           "logsumexp_rows", "m_step", "mahalanobis2", "removal_gain"]

_EPS10 = 10.0 * np.finfo(float).eps  # sklearn adds this to n_j so that no n_j is 0
_TWO_PI = 2.0 * np.pi
_COV_ROWS = np.array([0, 2, 2, 1])  # rows of (Σxx, Σyy, Σxy) giving [[Σxx, Σxy], [Σxy, Σyy]]

#: A pruning rule: normalised Gaussian weights (K,) → mask of the components to keep.
PruneRule = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class EMResult:
    """Outcome of :func:`fit_em`.

    ``log_likelihood`` is the mean log-likelihood ``L`` at the final parameters (what
    ``GaussianMixture.score`` returns); ``n_iter`` the EM iterations run; ``converged``
    whether the relative-change rule stopped it; ``n_pruned`` the components deleted;
    ``log_density`` the plots' ``log c(z_i)`` under ``mixture``, the floats of
    ``mixture.log_pdf(z)`` (the same elementwise formulas on the same operands, and each
    plot's sum over components taken alone).
    """

    mixture: Mixture
    log_likelihood: float
    n_iter: int
    converged: bool
    n_pruned: int
    log_density: np.ndarray | None = field(default=None, compare=False, repr=False)


def e_step(
    z: np.ndarray, mix: Mixture, sample_weight: np.ndarray | None = None
) -> tuple[float, np.ndarray]:
    """P1 eq. 9. Returns the mean log-likelihood ``L`` and the (n, K+1) responsibilities
    (column 0 the background), computed as ``exp(log π_j f_j − logsumexp)``."""
    wlp = mix.weighted_log_prob(z)
    norm = logsumexp_rows(wlp)
    return _mean_ll(norm, sample_weight), np.exp(wlp - norm[:, None])


def _mean_ll(norm: np.ndarray, sample_weight: np.ndarray | None) -> float:
    """``L = (1/Σs) Σ_i s_i log c(z_i)`` from the plots' ``log c`` (unweighted: ``mean``'s
    own sum and division, :func:`mhtrack.kernels.mean`)."""
    if sample_weight is None:
        return float(mean(norm))
    return float(sample_weight @ norm / sample_weight.sum())


def m_step(
    z: np.ndarray,
    resp: np.ndarray,
    background_box: tuple[float, float, float, float] | None,
    *,
    sample_weight: np.ndarray | None = None,
    reg_covar: float = 1e-6,
    background_floor: float = 0.0,
) -> tuple[Mixture, np.ndarray]:
    """P1 eqs. 10–11 (scikit-learn's ``_estimate_gaussian_parameters``, full covariances).

    Returns the new mixture and the effective counts ``n_j`` of the Gaussians.
    """
    w, means, q, w0, nk, _ = _m_step(z, plots_t(z), resp.T, background_box, sample_weight,
                                     reg_covar, background_floor)
    return Mixture(w, means, _cov(q), w0, background_box), nk


def _m_step(
    z: np.ndarray, z_t: np.ndarray, resp_t: np.ndarray,
    box: tuple[float, float, float, float] | None, sample_weight: np.ndarray | None,
    reg_covar: float, background_floor: float,
    sums: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, np.ndarray, np.ndarray]:
    """:func:`m_step` from the (K+1, n) responsibilities: the new weights, means, (3, K)
    covariance entries ``Σxx, Σyy, Σxy`` (:func:`_cov`), background weight, the counts
    ``n_j`` and the (2, K, n) offsets ``z_i − μ_j`` to the new means. ``sums``: a row-major
    (n, ≥ K+1) array whose first K+1 columns are the responsibilities, and their column
    sums, if at hand (no sample weights). The means are the plot-major
    ``(r[:, 1:].T @ z) / n_j``: one BLAS product on the row-major (n, K+1) operand of the
    formula."""
    r_t = resp_t if sample_weight is None else resp_t * sample_weight
    k = r_t.shape[0] - 1
    if sums is None:
        r = np.ascontiguousarray(r_t.T)
        col = sum_(r, axis=0)
    else:
        r, col = np.ascontiguousarray(sums[0][:, :k + 1]), sums[1]
    nk_all = col + _EPS10
    total = sum_(nk_all)
    nk = nk_all[1:]
    means = (r[:, 1:].T @ z) / nk[:, None]
    d = offsets_t(z_t, means)
    prods = np.empty((3 * k, len(z)))  # Σ r dx², Σ r dy², Σ r dx dy: one sum of 3K rows
    rd = r_t[1:] * d  # r dx, r dy
    np.multiply(rd, d, out=prods[:2 * k].reshape(2, k, -1))
    np.multiply(rd[0], d[1], out=prods[2 * k:])
    q = plot_sums(prods, k).reshape(3, k) / nk
    q[:2] += reg_covar
    if box is None:
        w0 = 0.0
        w = nk / sum_(nk)
    else:
        w0 = float(max(nk_all[0] / total, background_floor))
        g = sum_(nk)
        w = (1.0 - w0) * nk / g if g > 0 else nk * 0.0
    return w, means, q, w0, nk, d


def _cov(q: np.ndarray) -> np.ndarray:
    """(K, 2, 2) ``[[Σxx, Σxy], [Σxy, Σyy]]`` from the (3, K) rows ``Σxx, Σyy, Σxy``."""
    return q.take(_COV_ROWS, axis=0).T.reshape(q.shape[1], 2, 2)


def fit_em(
    z: np.ndarray,
    init: Mixture,
    *,
    sample_weight: np.ndarray | None = None,
    reg_covar: float = 1e-6,
    tol: float = 1e-4,
    max_iter: int = 100,
    prune: PruneRule | None = None,
    min_points: float = 0.0,
    background_floor: float = 0.0,
    min_contrast: float = 0.0,
    bic: bool = False,
    init_log_pdf: np.ndarray | None = None,
) -> EMResult:
    """Run EM (P1 eqs. 9–11, plus optional pruning, P1 step c) from ``init``.

    Parameters
    ----------
    z : (n, 2) data, n ≥ 1, finite (not checked here: callers validate at their edge).
    init : starting mixture (its ``background_box`` is kept fixed).
    sample_weight : (n,) non-negative weights ``s_i`` or ``None`` (all 1).
    reg_covar : added to the covariance diagonals (m²), as scikit-learn.
    tol : relative tolerance ``ε`` of P1 step 3, ``|ΔL| < ε|L|``; 0 runs ``max_iter``.
    max_iter : most EM iterations (one E-step and one M-step each, as scikit-learn).
    prune : rule applied to the normalised Gaussian weights after each M-step.
    min_points : delete Gaussians with ``n_j`` below this after each M-step.
    background_floor : lower bound on ``π₀`` (with a background box).
    min_contrast : with a background, delete Gaussians whose peak density
        ``π_j / (2π√|Σ_j|)`` is below ``min_contrast · π₀ / A`` after each M-step.
    bic : with a background, delete Gaussians whose :func:`removal_gain` is below the BIC
        price of their six parameters (2 mean, 3 covariance, 1 weight),
        ``½·6·ln n = 3 ln n`` nats for ``n`` (weighted) plots (Schwarz 1978).
    init_log_pdf : (K, n) log-densities ``log N(z_i; μ_j, Σ_j)`` of ``init``'s Gaussians
        (:func:`~mhtrack.clutter.density.log_pdf_t`) when the caller has them.

    With ``prune=None``, ``min_points=0``, no background and no sample weights, this is
    scikit-learn's ``GaussianMixture(covariance_type="full")`` EM from the same
    initialisation: after ``max_iter`` iterations ``log_likelihood`` equals its ``score``.
    """
    # Each mixture's Gaussian log-densities are computed once: the E-step of the next
    # iteration, the BIC test and the final L reuse them, and a deletion keeps the
    # surviving rows (elementwise formulas: the same floats as recomputing them). The
    # M-step's offsets z − μ and the determinants serve the densities and the contrast
    # test. The mixture is held as its arrays (covariances as the M-step's (3, K) rows)
    # and assembled once at the end. Every float is the one the plain loop over
    # e_step/m_step gives (tests/clutter/test_em.py).
    z_t = plots_t(z)
    box = init.background_box
    area = init.background_area
    with np.errstate(divide="ignore"):
        # the box is fixed; inside it log u is one number, bg0 (the usual case: the box
        # holds the data)
        log_bg, bg0 = init.log_background_const(z)
        log_u = log_bg if bg0 is None else bg0  # row 0 of weighted_t: one number, or per plot
        price = 3.0 * np.log(max(float(len(z) if sample_weight is None
                                       else sample_weight.sum()), 1.0)) if bic else 0.0
        w, means, w0 = init.weights, init.means, init.background_weight
        q: np.ndarray | None = None  # None: the covariances are init's
        glp = init_log_pdf
        if glp is None:
            glp = log_pdf_t(*maha_det_t(*offsets_t(z_t, means), init.covariances))
        wlp = weighted_t(w0, w, glp, log_u)
        norm: np.ndarray | None = None
        resp: np.ndarray | None = None
        sums: tuple[np.ndarray, np.ndarray] | None = None
        prev = -np.inf
        converged = False
        n_pruned = 0
        n_iter = 0
        for n_iter in range(1, max_iter + 1):  # noqa: B007
            if norm is None or resp is None:  # E-step (P1 eq. 9)
                norm, resp = responsibilities_t(wlp)
            ll = _mean_ll(norm, sample_weight)
            w, means, q, w0, nk, dxy = _m_step(z, z_t, resp, box, sample_weight, reg_covar,
                                               background_floor, sums)
            maha, det = sym_mahalanobis2(*dxy, q[0, :, None], q[2, :, None], q[1, :, None])
            glp = log_pdf_t(maha, det)
            wlp, norm, resp, sums = weighted_t(w0, w, glp, log_u), None, None, None
            keep = nk >= min_points
            k = len(w)
            if min_contrast > 0 and box is not None:
                peak = w / (_TWO_PI * np.sqrt(det[:, 0]))  # det2(Σ) = |Σ|
                keep &= peak >= min_contrast * w0 / area
            if bic and box is not None and k:
                norm = _lse_t(wlp)
                resp, gain, sums = _e_step_gain(w, wlp, norm, log_bg, sample_weight, bg0)
                keep &= gain >= price
            deleted = k - int(np.count_nonzero(keep))
            if prune is not None and deleted < k:
                wk = np.where(keep, w, 0.0) if deleted else w  # the same floats as where's
                keep &= prune(wk / sum_(wk))
                deleted = k - int(np.count_nonzero(keep))
            if deleted and not (any_(keep) or box is not None):
                deleted = 0  # nothing would be left: keep the components, not an empty model
            if deleted:  # keep the Gaussians kept; renormalise them to 1 − π₀ (P1 after eq. 12)
                kept = keep.nonzero()[0]  # np.flatnonzero's indices
                w = w.take(kept)
                s = sum_(w)
                if s > 0:
                    w = w * (1.0 - w0) / s
                if not len(w):
                    w0 = 1.0 if box is not None else 0.0
                means, q = means.take(kept, axis=0), q.take(kept, axis=1)
                n_pruned += deleted
                wlp, norm, resp, sums = (weighted_t(w0, w, glp.take(kept, axis=0), log_u), None,
                                         None, None)
            if not len(w):
                break
            if not deleted and abs(ll - prev) < tol * abs(prev):
                converged = True
                break
            prev = ll
        last = _lse_t(wlp) if norm is None else norm
    final = (_mean_ll(last, None) if sample_weight is None
             else float(np.average(last, weights=sample_weight)))
    mix = init if q is None else Mixture(w, means, _cov(q), w0, box)
    return EMResult(mix, final, n_iter, converged, n_pruned, last)


def removal_gain(
    z: np.ndarray, mix: Mixture, sample_weight: np.ndarray | None = None
) -> np.ndarray:
    """Per Gaussian ``j``, the log-likelihood (nats) the mixture loses when ``j`` is removed
    and its weight given to the uniform background:
    ``ΔL_j = Σ_i s_i [ln c(z_i) − ln(c(z_i) − π_j 𝒩_j(z_i) + π_j/A)]``
    ``= −Σ_i s_i ln(1 − r_ij + π_j/(A c(z_i)))`` with ``r_ij`` the responsibility.
    A Gaussian fitted to the fluctuations of uniform clutter gains little over the
    background it takes weight from; a clump, or a broad Gaussian under which the plots are
    denser than elsewhere, gains many nats. Needs a background box."""
    wlp = mix.weighted_log_prob(z)
    norm = logsumexp_rows(wlp)
    with np.errstate(divide="ignore"):
        return _removal_gain(mix.weights, np.exp(wlp[:, 1:] - norm[:, None]).T, norm,
                             mix.log_background(z), sample_weight)


def _e_step_gain(
    weights: np.ndarray, wlp: np.ndarray, norm: np.ndarray, log_bg: np.ndarray,
    sample_weight: np.ndarray | None, bg0: float | None,
) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray] | None]:
    """The (K+1, n) responsibilities ``exp(wlp − norm)``, :func:`removal_gain` and, for the
    next M-step, the row-major responsibilities with their column sums. The responsibilities
    and the terms of the gain sit side by side in one (n, 2K+1) row-major array summed once
    (:func:`~mhtrack.clutter.density.plot_sums`: each column as alone, for K ≥ 2); the
    M-step copies out the responsibilities' columns only if it runs on them."""
    k = len(weights)
    if sample_weight is not None or k < 2:
        resp = np.subtract(wlp, norm)
        np.exp(resp, out=resp)
        return resp, _removal_gain(weights, resp[1:], norm, log_bg, sample_weight, bg0), None
    both = np.empty((2 * k + 1, len(norm)))
    resp = np.subtract(wlp, norm, out=both[:k + 1])
    np.exp(resp, out=resp)
    _neg_log_ratio(weights, resp[1:], norm, log_bg, bg0, both[k + 1:])
    nat = np.ascontiguousarray(both.T)
    col = sum_(nat, axis=0)
    return resp, col[k + 1:], (nat, col[:k + 1])


def _removal_gain(
    weights: np.ndarray, resp: np.ndarray, norm: np.ndarray, log_bg: np.ndarray,
    sample_weight: np.ndarray | None, bg0: float | None = None,
) -> np.ndarray:
    """:func:`removal_gain` from the Gaussians' (K, n) responsibilities, the plots'
    ``log c(z_i)`` and the background's ``log u(z_i)`` (``bg0``: its value if the same for
    every plot). The caller ignores divide-by-zero warnings (``log π_j = −∞``)."""
    per = _neg_log_ratio(weights, resp, norm, log_bg, bg0, np.empty(resp.shape))
    if sample_weight is None:
        return plot_sums(per, len(per))
    return sample_weight @ np.ascontiguousarray(per.T)


def _neg_log_ratio(weights: np.ndarray, resp: np.ndarray, norm: np.ndarray, log_bg: np.ndarray,
                   bg0: float | None, out: np.ndarray) -> np.ndarray:
    """(K, n) terms ``−log max(1 − r_ij + π_j u(z_i)/c(z_i), 1e−300)`` of the gain, in
    ``out``."""
    if bg0 is None:
        to_bg = np.add(np.log(weights)[:, None], log_bg)
        to_bg -= norm
    else:  # (log π_j + log u) − log c per element, as above, with log u one number
        to_bg = np.subtract((np.log(weights) + bg0)[:, None], norm)
    np.exp(to_bg, out=to_bg)
    np.subtract(1.0, resp, out=out)
    out += to_bg
    np.maximum(out, 1e-300, out=out)
    np.log(out, out=out)
    return np.negative(out, out=out)
