"""The 2×2 closed forms against numpy.linalg and scipy.stats on random matrices."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import multivariate_normal

from mhtrack.models import linalg2


def _spd(rng: np.random.Generator, n: int) -> np.ndarray:
    A = rng.normal(size=(n, 2, 2)) * rng.uniform(0.1, 1e3, size=(n, 1, 1))
    return A @ np.swapaxes(A, -1, -2) + 1e-3 * np.eye(2)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_against_numpy_linalg(seed: int) -> None:
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(7, 2, 2))
    # a determinant is a difference of products: its rounding error scales with them
    scale = np.abs(A[:, 0, 0] * A[:, 1, 1]) + np.abs(A[:, 0, 1] * A[:, 1, 0])
    assert np.all(np.abs(linalg2.det2(A) - np.linalg.det(A)) <= 1e-14 * scale + 1e-300)
    np.testing.assert_allclose(linalg2.inv2(A) @ A, np.broadcast_to(np.eye(2), A.shape),
                               atol=1e-6 * np.abs(linalg2.inv2(A)).max())
    S = _spd(rng, 7)
    delta = rng.normal(size=(7, 2)) * 100
    d2, det = linalg2.mahalanobis2(delta, S)
    ref = np.einsum("ni,nij,nj->n", delta, np.linalg.inv(S), delta)
    np.testing.assert_allclose(d2, ref, rtol=1e-7)
    # as for det2 above: the rounding error of ac − b² scales with the products, not with
    # the (here possibly much smaller) determinant
    prods = np.abs(S[:, 0, 0] * S[:, 1, 1]) + S[:, 0, 1] ** 2
    assert np.all(np.abs(det - np.linalg.det(S)) <= 1e-14 * prods)
    np.testing.assert_allclose(linalg2.lmax2(S), np.linalg.eigvalsh(S)[:, -1], rtol=1e-9)


def test_sym_det_of_a_nearly_singular_covariance() -> None:
    """The case that showed it (hypothesis, seed 6495042): ``det`` 3 308.75 from products
    ~10¹¹ agrees with ``np.linalg.det`` to the products' rounding, not to 1e−9 of itself."""
    rng = np.random.default_rng(6495042)
    rng.normal(size=(7, 2, 2))  # the draws of the test above before its S
    S = _spd(rng, 7)
    _, det = linalg2.mahalanobis2(np.zeros((7, 2)), S)
    prods = np.abs(S[:, 0, 0] * S[:, 1, 1]) + S[:, 0, 1] ** 2
    assert np.all(np.abs(det - np.linalg.det(S)) <= 1e-14 * prods)


def test_gaussian_loglik_against_scipy() -> None:
    rng = np.random.default_rng(3)
    S = _spd(rng, 5)
    delta = rng.normal(size=(5, 2)) * 30
    d2, det = linalg2.mahalanobis2(delta, S)
    ours = linalg2.gaussian_loglik2(d2, det)
    ref = [multivariate_normal(mean=np.zeros(2), cov=S[i]).logpdf(delta[i]) for i in range(5)]
    np.testing.assert_allclose(ours, ref, rtol=1e-9)


def test_hand_worked() -> None:
    # S = [[4, 1], [1, 2]]: det 7, S⁻¹ = [[2, −1], [−1, 4]]/7; Δ = (1, 2): Δᵀ S⁻¹ Δ
    # = (2 − 4 + 16)/7 = 2; λmax = 3 + sqrt(9 − 7) = 3 + √2.
    S = np.array([[4.0, 1.0], [1.0, 2.0]])
    d2, det = linalg2.mahalanobis2(np.array([1.0, 2.0]), S)
    assert d2 == 2.0 and det == 7.0
    assert np.isclose(linalg2.lmax2(S), 3 + np.sqrt(2))
