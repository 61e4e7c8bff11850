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
All 2×2 arithmetic is closed-form (:mod:`mhtrack.models.linalg2`) on whole ``(n, K)`` arrays.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mhtrack.models.linalg2 import LOG_2PI, det2, sym_det2, sym_mahalanobis2

_EPS10 = 10.0 * np.finfo(float).eps  # sklearn adds this to n_j so that no n_j is 0

#: A pruning rule: normalised Gaussian weights (K,) → mask of the components to keep.
PruneRule = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Mixture:
    """Gaussian mixture in 2-D with an optional uniform background component.

    Attributes
    ----------
    weights : (K,) Gaussian weights ``π_j``; ``weights.sum() + background_weight == 1``.
    means : (K, 2) means ``μ_j`` (m).
    covariances : (K, 2, 2) covariances ``Σ_j`` (m²).
    background_weight : ``π₀`` (0 without a background).
    background_box : ``(xmin, xmax, ymin, ymax)`` of the uniform background, or ``None``.
    """

    weights: np.ndarray
    means: np.ndarray
    covariances: np.ndarray
    background_weight: float = 0.0
    background_box: tuple[float, float, float, float] | None = None

    @property
    def n_components(self) -> int:
        """Number of Gaussian components ``K``."""
        return len(self.weights)

    @property
    def background_area(self) -> float:
        """Area ``A`` of the background box (m²); ``inf`` without one."""
        if self.background_box is None:
            return float("inf")
        x0, x1, y0, y1 = self.background_box
        return (x1 - x0) * (y1 - y0)

    def log_background(self, z: np.ndarray) -> np.ndarray:
        """``log u(z)``: ``−log A`` inside the box, ``−inf`` outside (or without a box)."""
        if self.background_box is None:
            return np.full(len(z), -np.inf)
        x0, x1, y0, y1 = self.background_box
        inside = (z[:, 0] >= x0) & (z[:, 0] <= x1) & (z[:, 1] >= y0) & (z[:, 1] <= y1)
        return np.where(inside, -np.log(self.background_area), -np.inf)

    def weighted_log_prob(self, z: np.ndarray) -> np.ndarray:
        """(n, K+1) ``log π_j + log f_j(z)``; column 0 the background (``−inf`` if none)."""
        return _weighted(self, gaussian_log_pdf(z, self.means, self.covariances),
                         self.log_background(z))

    def log_pdf(self, z: np.ndarray) -> np.ndarray:
        """``log c(z)`` (P1 eqs. 6, 13) at (n, 2) positions."""
        return logsumexp_rows(self.weighted_log_prob(z))

    def pdf(self, z: np.ndarray) -> np.ndarray:
        """``c(z)`` (P1 eq. 13), per m², at (n, 2) positions; 0 where it underflows.

        For many positions (maps, quadrature) each Gaussian is evaluated only inside the
        axis-aligned box ``|Δx| ≤ r√Σxx, |Δy| ≤ r√Σyy`` with ``r² = 1490``: outside it
        ``exp(−½ dᵀΣ⁻¹d) < e⁻⁷⁴⁵`` underflows to 0 anyway, so the result is the same.
        """
        z = np.asarray(z, dtype=float)
        if len(z) * max(self.n_components, 1) <= 65_536:
            return np.exp(self.log_pdf(z))
        out = self.background_weight * np.exp(self.log_background(z))
        a, b, c = self.covariances[:, 0, 0], self.covariances[:, 0, 1], self.covariances[:, 1, 1]
        norm = self.weights / (2.0 * np.pi * np.sqrt(sym_det2(a, b, c)))
        r = np.sqrt(1490.0)
        for j in range(self.n_components):
            dx, dy = z[:, 0] - self.means[j, 0], z[:, 1] - self.means[j, 1]
            sel = np.flatnonzero((np.abs(dx) <= r * np.sqrt(a[j]))
                                 & (np.abs(dy) <= r * np.sqrt(c[j])))
            q, _ = sym_mahalanobis2(dx[sel], dy[sel], a[j], b[j], c[j])
            out[sel] += norm[j] * np.exp(-0.5 * q)
        return out

    def to_state(self) -> dict[str, object]:
        """JSON-able values and arrays (inverse: :meth:`from_state`)."""
        return {
            "weights": self.weights.copy(),
            "means": self.means.copy(),
            "covariances": self.covariances.copy(),
            "background_weight": float(self.background_weight),
            "background_box": None if self.background_box is None
            else [float(v) for v in self.background_box],
        }

    @classmethod
    def from_state(cls, s: dict[str, object]) -> Mixture:
        """Rebuild a mixture from :meth:`to_state`'s output."""
        box = s["background_box"]
        return cls(
            np.asarray(s["weights"], float).reshape(-1),
            np.asarray(s["means"], float).reshape(-1, 2),
            np.asarray(s["covariances"], float).reshape(-1, 2, 2),
            float(s["background_weight"]),  # type: ignore[arg-type]
            None if box is None else tuple(float(v) for v in box),  # type: ignore[arg-type]
        )


@dataclass(frozen=True)
class EMResult:
    """Outcome of :func:`fit_em`.

    ``log_likelihood`` is the mean log-likelihood ``L`` at the final parameters (what
    ``GaussianMixture.score`` returns); ``n_iter`` the EM iterations run; ``converged``
    whether the relative-change rule stopped it; ``n_pruned`` the components deleted.
    """

    mixture: Mixture
    log_likelihood: float
    n_iter: int
    converged: bool
    n_pruned: int


def logsumexp_rows(a: np.ndarray) -> np.ndarray:
    """``log Σ_j exp(a_ij)`` per row, stable; ``−inf`` for a row of ``−inf``."""
    if a.shape[1] == 0:
        return np.full(a.shape[0], -np.inf)
    m = a.max(axis=1)
    m_safe = np.where(np.isfinite(m), m, 0.0)
    with np.errstate(divide="ignore"):
        return np.log(np.exp(a - m_safe[:, None]).sum(axis=1)) + m_safe


def gaussian_log_pdf(z: np.ndarray, means: np.ndarray, covariances: np.ndarray) -> np.ndarray:
    """(n, K) ``log N(z_i; μ_j, Σ_j) = −log 2π − ½ log|Σ| − ½ dᵀΣ⁻¹d`` (this sum order, not
    :func:`~mhtrack.models.linalg2.gaussian_loglik2`'s, which rounds differently)."""
    maha, det = _maha_det(z, means, covariances)
    return -LOG_2PI - 0.5 * np.log(det) - 0.5 * maha


def mahalanobis2(z: np.ndarray, means: np.ndarray, covariances: np.ndarray) -> np.ndarray:
    """(n, K) squared Mahalanobis distances ``dᵀΣ_j⁻¹d`` of every plot to every component."""
    return _maha_det(z, means, covariances)[0]


def _maha_det(z: np.ndarray, means: np.ndarray, cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, K) ``dᵀΣ_j⁻¹d`` and (K,) ``|Σ_j|`` (``linalg2.sym_mahalanobis2``)."""
    return sym_mahalanobis2(z[:, 0:1] - means[:, 0], z[:, 1:2] - means[:, 1],
                            cov[:, 0, 0], cov[:, 0, 1], cov[:, 1, 1])


def e_step(
    z: np.ndarray, mix: Mixture, sample_weight: np.ndarray | None = None
) -> tuple[float, np.ndarray]:
    """P1 eq. 9. Returns the mean log-likelihood ``L`` and the (n, K+1) responsibilities
    (column 0 the background), computed as ``exp(log π_j f_j − logsumexp)``."""
    wlp = mix.weighted_log_prob(z)
    norm = logsumexp_rows(wlp)
    return _mean_ll(norm, sample_weight), np.exp(wlp - norm[:, None])


def _weighted(mix: Mixture, glp: np.ndarray, log_bg: np.ndarray) -> np.ndarray:
    """(n, K+1) ``log π_j + log f_j(z)`` from the Gaussians' (n, K) ``log N`` and the
    background's (n,) ``log u``: the one formula of :meth:`Mixture.weighted_log_prob`."""
    out = np.empty((len(log_bg), mix.n_components + 1))
    with np.errstate(divide="ignore"):
        out[:, 0] = np.log(mix.background_weight) + log_bg
        out[:, 1:] = np.log(mix.weights) + glp
    return out


def _mean_ll(norm: np.ndarray, sample_weight: np.ndarray | None) -> float:
    """``L = (1/Σs) Σ_i s_i log c(z_i)`` from the rows' ``log c``."""
    if sample_weight is None:
        return float(norm.mean())
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
    r = resp if sample_weight is None else resp * sample_weight[:, None]
    nk_all = r.sum(axis=0) + _EPS10
    total = nk_all.sum()
    nk = nk_all[1:]
    rg = r[:, 1:]
    means = (rg.T @ z) / nk[:, None]
    dx = z[:, 0:1] - means[:, 0]
    dy = z[:, 1:2] - means[:, 1]
    cov = np.empty((len(nk), 2, 2))
    cov[:, 0, 0] = (rg * dx * dx).sum(axis=0) / nk + reg_covar
    cov[:, 1, 1] = (rg * dy * dy).sum(axis=0) / nk + reg_covar
    cov[:, 0, 1] = cov[:, 1, 0] = (rg * dx * dy).sum(axis=0) / nk
    if background_box is None:
        w0 = 0.0
        w = nk / nk.sum()
    else:
        w0 = max(nk_all[0] / total, background_floor)
        g = nk.sum()
        w = (1.0 - w0) * nk / g if g > 0 else nk * 0.0
    return Mixture(w, means, cov, float(w0), background_box), nk


def _drop(mix: Mixture, keep: np.ndarray) -> Mixture:
    """Keep the Gaussians in ``keep``; renormalise them to ``1 − π₀`` (P1 after eq. 12)."""
    w = mix.weights[keep]
    s = w.sum()
    if s > 0:
        w = w * (1.0 - mix.background_weight) / s
    bg = mix.background_weight if len(w) else (1.0 if mix.background_box is not None else 0.0)
    return Mixture(w, mix.means[keep], mix.covariances[keep], bg, mix.background_box)


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

    With ``prune=None``, ``min_points=0``, no background and no sample weights, this is
    scikit-learn's ``GaussianMixture(covariance_type="full")`` EM from the same
    initialisation: after ``max_iter`` iterations ``log_likelihood`` equals its ``score``.
    """
    # Each mixture's (n, K) Gaussian log-densities are computed once: the E-step of the
    # next iteration, the BIC test and the final L reuse them, and a deletion keeps the
    # surviving columns (elementwise formulas: the same floats as recomputing them).
    log_bg = init.log_background(z)  # the box is fixed
    mix = init
    wlp = _weighted(mix, gaussian_log_pdf(z, mix.means, mix.covariances), log_bg)
    norm: np.ndarray | None = None
    resp: np.ndarray | None = None
    prev = -np.inf
    converged = False
    n_pruned = 0
    n_iter = 0
    for n_iter in range(1, max_iter + 1):  # noqa: B007
        if norm is None or resp is None:  # E-step (P1 eq. 9)
            norm = logsumexp_rows(wlp)
            resp = np.exp(wlp - norm[:, None])
        ll = _mean_ll(norm, sample_weight)
        mix, nk = m_step(z, resp, mix.background_box, sample_weight=sample_weight,
                         reg_covar=reg_covar, background_floor=background_floor)
        glp = gaussian_log_pdf(z, mix.means, mix.covariances)
        wlp, norm, resp = _weighted(mix, glp, log_bg), None, None
        keep = nk >= min_points
        if min_contrast > 0 and mix.background_box is not None:
            peak = mix.weights / (2.0 * np.pi * np.sqrt(det2(mix.covariances)))
            keep &= peak >= min_contrast * mix.background_weight / mix.background_area
        if bic and mix.background_box is not None and mix.n_components:
            n_eff = float(len(z) if sample_weight is None else sample_weight.sum())
            norm = logsumexp_rows(wlp)
            resp = np.exp(wlp - norm[:, None])
            gain = _removal_gain(mix, resp[:, 1:], norm, log_bg, sample_weight)
            keep &= gain >= 3.0 * np.log(max(n_eff, 1.0))
        if prune is not None and keep.any():
            w = np.where(keep, mix.weights, 0.0)
            keep &= prune(w / w.sum())
        deleted = int((~keep).sum())
        if deleted and not (keep.any() or mix.background_box is not None):
            deleted = 0  # nothing would be left: keep the components, not an empty model
        if deleted:
            mix = _drop(mix, keep)
            n_pruned += deleted
            wlp, norm, resp = _weighted(mix, glp[:, keep], log_bg), None, None
        if mix.n_components == 0:
            break
        if not deleted and abs(ll - prev) < tol * abs(prev):
            converged = True
            break
        prev = ll
    final = float(np.average(logsumexp_rows(wlp) if norm is None else norm,
                             weights=sample_weight))
    return EMResult(mix, final, n_iter, converged, n_pruned)


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
    return _removal_gain(mix, np.exp(wlp[:, 1:] - norm[:, None]), norm,
                         mix.log_background(z), sample_weight)


def _removal_gain(
    mix: Mixture, resp: np.ndarray, norm: np.ndarray, log_bg: np.ndarray,
    sample_weight: np.ndarray | None,
) -> np.ndarray:
    """:func:`removal_gain` from the Gaussians' (n, K) responsibilities, the rows'
    ``log c(z_i)`` and the background's ``log u(z_i)``."""
    with np.errstate(divide="ignore"):
        to_bg = np.exp(np.log(mix.weights)[None, :] + log_bg[:, None] - norm[:, None])
    ratio = np.maximum(1.0 - resp + to_bg, 1e-300)
    per = -np.log(ratio)
    return per.sum(axis=0) if sample_weight is None else sample_weight @ per
