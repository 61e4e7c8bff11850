"""The clutter density ``c(z)``: a 2-D Gaussian mixture with an optional uniform background
(P1 eq. 6), and the array pieces EM (:mod:`mhtrack.clutter.em`) computes it from.

    c(z) = π₀ u(z) + Σ_{j=1..K} π_j N(z; μ_j, Σ_j),      π₀ + Σ π_j = 1,       (P1 eq. 6)

``u(z) = 1/A`` on an axis-aligned box of area ``A`` (0 outside); without a box ``π₀ = 0``.

*Layout.* The (plots × components) arrays are held component-major, ``(K, n)``: NumPy runs
an elementwise operation between a ``(K, n)`` array and a ``(K, 1)`` column as K loops of
n elements, and the same operation between ``(n, K)`` and ``(K,)`` as n loops of K
elements — several times slower for the few components of a clutter mixture. Elementwise
results do not depend on the layout; sums do, so every sum is taken as NumPy takes it on
the plot-major ``(n, K)`` array of the formulas (:func:`plot_sums`, :func:`_lse_t`): the
floats are those of the plot-major code, bit for bit (``tests/clutter/test_em.py``).
"""

from __future__ import annotations

from dataclasses import dataclass
from math import isfinite

import numpy as np

from mhtrack.kernels import max_, min_, sum_
from mhtrack.models.linalg2 import LOG_2PI, sym_det2, sym_mahalanobis2


def plot_sums(a_t: np.ndarray, width: int) -> np.ndarray:
    """``a.sum(axis=0)`` of the row-major ``(n, width)`` array ``a`` given as ``a_t`` (its
    rows ``a_t[j]``, or blocks of ``width`` of them, are the columns of ``a``).

    NumPy sums each column of a row-major array of two or more columns one row after the
    other, whatever the number of columns: the column sums of ``a_t``'s row-major transpose
    are those of ``a`` (and of several such arrays side by side). A lone column (``width``
    1) is summed as a contiguous vector (pairwise), which each row of ``a_t`` is."""
    if width < 2:
        return sum_(a_t, axis=1)
    return sum_(np.ascontiguousarray(a_t.T), axis=0)


def _lse_t(a_t: np.ndarray) -> np.ndarray:
    """``log Σ_j exp(a_ij)`` per plot of the component-major ``a_t`` (≥ 1 row); the
    maximum (exact in any order) over ``a_t``, the sum over components as
    ``.sum(axis=1)`` of the plot-major row-major array. Caller ignores log 0 warnings."""
    m = max_(a_t, axis=0)
    # a finite sum: every maximum is finite, and np.where would copy m as it is
    m_safe = m if isfinite(sum_(m)) else np.where(np.isfinite(m), m, 0.0)
    e = np.subtract(a_t, m_safe)
    np.exp(e, out=e)
    s = sum_(np.ascontiguousarray(e.T), axis=1)
    np.log(s, out=s)
    s += m_safe
    return s


def responsibilities_t(wlp_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The E-step (P1 eq. 9) of the component-major (K+1, n) ``log π_j + log f_j(z_i)``
    (:func:`weighted_t`): each plot's ``log c(z_i)`` (n,) and the responsibilities
    ``r_ij = exp(log π_j f_j(z_i) − log c(z_i))`` (K+1, n). Caller ignores log 0 warnings."""
    norm = _lse_t(wlp_t)
    resp = np.subtract(wlp_t, norm)
    np.exp(resp, out=resp)
    return norm, resp


def logsumexp_rows(a: np.ndarray) -> np.ndarray:
    """``log Σ_j exp(a_ij)`` per row, stable; ``−inf`` for a row of ``−inf``."""
    if a.shape[1] == 0:
        return np.full(a.shape[0], -np.inf)
    with np.errstate(divide="ignore"):
        return _lse_t(a.T)


def plots_t(z: np.ndarray, copy: bool = True) -> np.ndarray:
    """(2, 1, n) coordinates of (n, 2) plots, a row-major copy (or a view) for
    :func:`offsets_t`."""
    return (np.ascontiguousarray(z.T) if copy else z.T)[:, None, :]


def offsets_t(z_t: np.ndarray, means: np.ndarray) -> np.ndarray:
    """(2, K, n) ``x_i − μ_jx`` and ``y_i − μ_jy`` from :func:`plots_t`'s ``z_t``."""
    return z_t - means.T[:, :, None]


def maha_det_t(dx_t: np.ndarray, dy_t: np.ndarray, cov: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """(K, n) ``dᵀΣ_j⁻¹d`` and (K, 1) ``|Σ_j|`` (``linalg2.sym_mahalanobis2``)."""
    return sym_mahalanobis2(dx_t, dy_t, cov[:, 0, 0, None], cov[:, 0, 1, None],
                            cov[:, 1, 1, None])


def log_pdf_t(maha_t: np.ndarray, det: np.ndarray) -> np.ndarray:
    """(K, n) ``log N = −log 2π − ½ log|Σ| − ½ dᵀΣ⁻¹d`` (this sum order, not
    :func:`~mhtrack.models.linalg2.gaussian_loglik2`'s, which rounds differently)."""
    return -LOG_2PI - 0.5 * np.log(det) - 0.5 * maha_t


#: :meth:`Mixture.pdf` evaluates ``exp(log_pdf)`` directly up to this many plot×component
#: pairs, and by boxes around each Gaussian above.
PDF_DIRECT = 65_536



def gaussian_log_pdf(z: np.ndarray, means: np.ndarray, covariances: np.ndarray) -> np.ndarray:
    """(n, K) ``log N(z_i; μ_j, Σ_j)`` (:func:`log_pdf_t`)."""
    maha, det = maha_det_t(*offsets_t(plots_t(z), means), covariances)
    return np.ascontiguousarray(log_pdf_t(maha, det).T)


def mahalanobis2(z: np.ndarray, means: np.ndarray, covariances: np.ndarray) -> np.ndarray:
    """(n, K) squared Mahalanobis distances ``dᵀΣ_j⁻¹d`` of every plot to every component."""
    return np.ascontiguousarray(maha_det_t(*offsets_t(plots_t(z), means), covariances)[0].T)


def weighted_t(background_weight: float, weights: np.ndarray, glp_t: np.ndarray,
               log_bg: np.ndarray | np.floating) -> np.ndarray:
    """(K+1, n) ``log π_j + log f_j(z)`` from the weights ``π₀``, ``π_j``, the Gaussians'
    (K, n) ``log N`` and the background's (n,) ``log u`` (or its one value at every plot);
    row 0 the background. Caller ignores log 0 warnings."""
    out = np.empty((len(weights) + 1, glp_t.shape[1]))
    out[0] = np.log(background_weight) + log_bg
    np.add(np.log(weights)[:, None], glp_t, out=out[1:])
    return out


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
        return self.log_background_const(z)[0]

    def log_background_const(self, z: np.ndarray) -> tuple[np.ndarray, np.floating | None]:
        """:meth:`log_background` at (n ≥ 0, 2) ``z`` and its value when it is the same at
        every plot (``None`` otherwise)."""
        if self.background_box is None:
            out = np.full(len(z), -np.inf)
            return out, (out[0] if len(z) else None)
        x0, x1, y0, y1 = self.background_box
        x, y = z[:, 0], z[:, 1]
        if len(z) and (min_(x) >= x0 and max_(x) <= x1 and min_(y) >= y0 and max_(y) <= y1):
            out = np.full(len(z), -np.log(self.background_area))  # all inside the box
            return out, out[0]
        inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
        out = np.where(inside, -np.log(self.background_area), -np.inf)
        return out, (out[0] if len(out) and (out == out[0]).all() else None)

    def _weighted_t(self, z: np.ndarray) -> np.ndarray:
        """(K+1, n) :func:`weighted_t` at ``z``; caller ignores log 0 warnings."""
        maha, det = maha_det_t(*offsets_t(plots_t(z, copy=False), self.means),
                                self.covariances)
        return weighted_t(self.background_weight, self.weights, log_pdf_t(maha, det),
                          self.log_background(z))

    def weighted_log_prob(self, z: np.ndarray) -> np.ndarray:
        """(n, K+1) ``log π_j + log f_j(z)``; column 0 the background (``−inf`` if none)."""
        with np.errstate(divide="ignore"):
            return np.ascontiguousarray(self._weighted_t(z).T)

    def log_pdf(self, z: np.ndarray) -> np.ndarray:
        """``log c(z)`` (P1 eqs. 6, 13) at (n, 2) positions."""
        with np.errstate(divide="ignore"):
            return _lse_t(self._weighted_t(z))

    def pdf(self, z: np.ndarray) -> np.ndarray:
        """``c(z)`` (P1 eq. 13), per m², at (n, 2) positions; 0 where it underflows.

        For many positions (maps, quadrature) each Gaussian is evaluated only inside the
        axis-aligned box ``|Δx| ≤ r√Σxx, |Δy| ≤ r√Σyy`` with ``r² = 1490``: outside it
        ``exp(−½ dᵀΣ⁻¹d) < e⁻⁷⁴⁵`` underflows to 0 anyway, so the result is the same.
        """
        z = np.asarray(z, dtype=float)
        if len(z) * max(self.n_components, 1) <= PDF_DIRECT:
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
