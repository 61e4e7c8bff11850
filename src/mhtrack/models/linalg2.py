"""Closed-form linear algebra of stacked 2×2 matrices, the one home of these formulas.

Every 2-D position quantity in mhtrack — innovation covariances ``S`` (Kalman filter,
IMM), plot covariances ``R`` (fusion, births), mixture covariances ``Σ`` (EM) — is a
stack of 2×2 matrices; these functions work on the last two axes of any stack without a
Python loop and without ``numpy.linalg`` (whose LAPACK call per matrix costs more than the
arithmetic here). For a 2×2 matrix ``A = [[a, b], [c, d]]``::

    det A  = a d − b c
    A⁻¹    = [[d, −b], [−c, a]] / det A
    for symmetric S = [[a, b], [b, d]] and a 2-vector Δ = (x, y):
    Δᵀ S⁻¹ Δ = (d x² − 2 b x y + a y²) / (a d − b²)
    λmax(S) = tr/2 + sqrt(tr²/4 − det)
    ln N(Δ; 0, S) = −½ (Δᵀ S⁻¹ Δ + ln det S) − ln 2π

(e.g. Strang, *Introduction to Linear Algebra*, §5.3 and §6.1; the Gaussian density in
Bar-Shalom et al. 2001 §1.4.)
"""

from __future__ import annotations

import numpy as np

#: ``ln 2π``, the constant of a bivariate Gaussian log-density.
LOG_2PI = float(np.log(2 * np.pi))


def det2(A: np.ndarray) -> np.ndarray:
    """``det A = a d − b c`` of stacked (…, 2, 2) matrices (general, not only symmetric)."""
    return A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] * A[..., 1, 0]


def inv2(A: np.ndarray) -> np.ndarray:
    """``A⁻¹ = [[d, −b], [−c, a]] / det A`` of stacked (…, 2, 2) matrices."""
    det = det2(A)
    inv = np.empty(np.shape(A))
    inv[..., 0, 0] = A[..., 1, 1] / det
    inv[..., 1, 1] = A[..., 0, 0] / det
    inv[..., 0, 1] = -A[..., 0, 1] / det
    inv[..., 1, 0] = -A[..., 1, 0] / det
    return inv


def sym_det2(a: np.ndarray, b: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``a d − b²``: determinant of symmetric ``[[a, b], [b, d]]`` given its entries."""
    return a * d - b * b


def sym_mahalanobis2(
    x: np.ndarray, y: np.ndarray, a: np.ndarray, b: np.ndarray, d: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``Δᵀ S⁻¹ Δ = (d x² − 2 b x y + a y²) / (a d − b²)`` and ``det S`` for ``Δ = (x, y)``
    and symmetric ``S = [[a, b], [b, d]]`` given entrywise (broadcasting)."""
    det = sym_det2(a, b, d)
    return (d * x * x - 2 * b * x * y + a * y * y) / det, det


def mahalanobis2(delta: np.ndarray, S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``Δᵀ S⁻¹ Δ`` and ``det S`` over stacked 2-vectors (…, 2) and symmetric (…, 2, 2)
    matrices (only the upper triangle of ``S`` is read)."""
    return sym_mahalanobis2(delta[..., 0], delta[..., 1], S[..., 0, 0], S[..., 0, 1],
                            S[..., 1, 1])


def lmax2(S: np.ndarray) -> np.ndarray:
    """Largest eigenvalue ``tr/2 + sqrt(tr²/4 − det)`` of stacked symmetric 2×2 matrices
    (the square root's argument floored at 0 against rounding)."""
    tr = S[..., 0, 0] + S[..., 1, 1]
    det = S[..., 0, 0] * S[..., 1, 1] - S[..., 0, 1] ** 2
    return 0.5 * tr + np.sqrt(np.maximum(0.25 * tr * tr - det, 0.0))


def gaussian_loglik2(d2: np.ndarray, det: np.ndarray) -> np.ndarray:
    """``ln N(Δ; 0, S) = −½ (d² + ln det S) − ln 2π`` from ``d² = Δᵀ S⁻¹ Δ`` and ``det S``."""
    return -0.5 * (d2 + np.log(det)) - LOG_2PI
