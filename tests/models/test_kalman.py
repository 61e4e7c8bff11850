"""The general-form Kalman filter and gate of ``tests/reference/kalman_reference.py``
(what the library's fast paths are checked against) and the χ² gate threshold, against
hand-worked values, scipy and a per-track textbook loop."""

import kalman_reference as kalman
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import chi2, multivariate_normal

from mhtrack.mht.gating import gate_threshold
from mhtrack.models.motion import ConstantVelocity, H


def test_cv_matrices_hand_worked():
    m = ConstantVelocity(sigma_v=10.0)
    F = m.F(2.0)
    assert np.array_equal(F[:2, :2], [[1, 2], [0, 1]])
    assert np.array_equal(F[2:, 2:], [[1, 2], [0, 1]])
    assert np.all(F[:2, 2:] == 0)
    Q = m.Q(2.0)
    # Q1 = [[T^4/4, T^3/2], [T^3/2, T^2]] * sigma_v^2 with T = 2: [[4, 4], [4, 4]] * 100
    assert np.allclose(Q[:2, :2], [[400, 400], [400, 400]])
    assert np.allclose(Q[2:, 2:], [[400, 400], [400, 400]])


def test_gate_threshold_is_chi2_quantile():
    assert gate_threshold(0.99) == pytest.approx(-2 * np.log(0.01))
    with pytest.raises(ValueError, match="gate probability"):
        gate_threshold(1.0)


def _reference_update(x, P, z, R):
    S = H @ P @ H.T + R
    K = P @ H.T @ np.linalg.inv(S)
    xn = x + K @ (z - H @ x)
    Pn = (np.eye(4) - K @ H) @ P
    return xn, Pn


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_update_matches_textbook_form(seed):
    rng = np.random.default_rng(seed)
    K = 7
    A = rng.normal(size=(K, 4, 4))
    P = A @ A.transpose(0, 2, 1) + np.eye(4) * 10
    x = rng.normal(size=(K, 4)) * 100
    z = rng.normal(size=(K, 2)) * 100
    B = rng.normal(size=(K, 2, 2))
    R = B @ B.transpose(0, 2, 1) + np.eye(2)
    xn, Pn = kalman.update(x, P, z, R)
    for i in range(K):
        xr, Pr = _reference_update(x[i], P[i], z[i], R[i])
        assert np.allclose(xn[i], xr, rtol=1e-8, atol=1e-8)
        assert np.allclose(Pn[i], Pr, rtol=1e-7, atol=1e-7)


def test_loglik_matches_scipy():
    rng = np.random.default_rng(3)
    x = rng.normal(size=(4, 4)) * 50
    P = np.tile(np.diag([100.0, 10, 200, 10]), (4, 1, 1))
    z = rng.normal(size=(6, 2)) * 50
    R = np.array([[50.0, 10], [10, 80]])
    d2, ll = kalman.innovation_loglik(x, P, z, R)
    for i in range(4):
        S = H @ P[i] @ H.T + R
        for j in range(6):
            ref = multivariate_normal(H @ x[i], S).logpdf(z[j])
            assert ll[i, j] == pytest.approx(ref, rel=1e-10)
            nu = z[j] - H @ x[i]
            assert d2[i, j] == pytest.approx(nu @ np.linalg.solve(S, nu), rel=1e-10)


@pytest.mark.parametrize("n_plots", [50, 3000])  # dense path and k-d tree path
@pytest.mark.parametrize("per_plot_R", [False, True])
def test_gate_equals_dense_reference(n_plots, per_plot_R, monkeypatch):
    rng = np.random.default_rng(n_plots)
    M = 120
    x = np.column_stack([rng.uniform(-5e3, 5e3, M), rng.normal(size=M), rng.uniform(-5e3, 5e3, M),
                         rng.normal(size=M)])
    P = np.tile(np.diag([1e4, 100, 4e4, 100]), (M, 1, 1))
    z = rng.uniform(-5e3, 5e3, (n_plots, 2))
    R = (np.eye(2) * rng.uniform(1e3, 1e5, (n_plots, 1, 1))) if per_plot_R else np.eye(2) * 1e4
    gamma = chi2.ppf(0.999, 2)
    monkeypatch.setattr(kalman, "DENSE_PAIR_LIMIT", 10_000)
    g = kalman.gate(x, P, z, R, gamma)
    d2, ll = kalman.innovation_loglik(x, P, z, R)
    ti, pj = np.nonzero(d2 <= gamma)
    assert np.array_equal(g.track, ti) and np.array_equal(g.plot, pj)
    assert np.allclose(g.loglik, ll[ti, pj])
    assert len(g) > 0


def test_gate_handles_empty_inputs():
    g = kalman.gate(np.zeros((0, 4)), np.zeros((0, 4, 4)), np.ones((3, 2)), np.eye(2), 9.2)
    assert len(g) == 0
    P = np.tile(np.eye(4), (2, 1, 1))
    g = kalman.gate(np.zeros((2, 4)), P, np.zeros((0, 2)), np.eye(2), 9.2)
    assert len(g) == 0


def test_two_point_init_covariance_by_monte_carlo():
    rng = np.random.default_rng(0)
    R = np.array([[400.0, 50.0], [50.0, 900.0]])
    n = 200_000
    L = np.linalg.cholesky(R)
    z1 = (L @ rng.normal(size=(2, n))).T
    z2 = np.array([100.0, 0.0]) + (L @ rng.normal(size=(2, n))).T
    x, P = kalman.two_point_init(z1, z2, 2.0, R, R)
    truth = np.array([100.0, 50.0, 0.0, 0.0])
    err = x - truth
    assert np.allclose(err.mean(0), 0, atol=0.5)
    assert np.allclose(np.cov(err.T), P[0], rtol=0.03, atol=1.0)


@pytest.mark.parametrize("p", [0.5, 0.9, 0.99, 0.999, 0.999999])
def test_gate_threshold_matches_scipy_chi2(p):
    assert gate_threshold(p) == pytest.approx(chi2.ppf(p, df=2), rel=1e-12)
