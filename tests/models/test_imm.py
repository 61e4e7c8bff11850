"""The batched IMM of constant-velocity models (``mhtrack.models.imm``) against a plain
per-track, per-model implementation written out with explicit matrices."""

from __future__ import annotations

import math

import kalman_reference as kalman
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.models import imm
from mhtrack.models.kalman import predict_cv as cv_predict
from mhtrack.models.motion import ConstantVelocity

H = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])


def random_tracks(rng: np.random.Generator, M: int, r: int):
    xm = rng.normal(0, 500, (M, r, 4))
    A = rng.normal(0, 1, (M, r, 4, 4))
    Pm = A @ np.swapaxes(A, -1, -2) * 400 + np.eye(4) * 100
    mu = rng.dirichlet(np.ones(r), M)
    return xm, Pm, mu


def reference_step(x, P, mu, sigmas, tau, dt, z, R):
    """One IMM cycle for one track, textbook form (Bar-Shalom et al. 2001 §11.6.6)."""
    r = len(sigmas)
    stay = math.exp(-dt / tau)
    pi = np.full((r, r), (1 - stay) / (r - 1))
    np.fill_diagonal(pi, stay)
    F = ConstantVelocity.F(dt)
    cbar = np.array([sum(pi[i, j] * mu[i] for i in range(r)) for j in range(r)])
    xp, Pp, lik = [], [], []
    for j in range(r):
        w = [pi[i, j] * mu[i] / cbar[j] for i in range(r)]
        x0 = sum(w[i] * x[i] for i in range(r))
        P0 = sum(w[i] * (P[i] + np.outer(x[i] - x0, x[i] - x0)) for i in range(r))
        xj = F @ x0
        Pj = F @ P0 @ F.T + ConstantVelocity(sigmas[j]).Q(dt)
        S = H @ Pj @ H.T + R
        nu = z - H @ xj
        lik.append(math.exp(-0.5 * nu @ np.linalg.solve(S, nu)) / (2 * math.pi * math.sqrt(
            np.linalg.det(S))))
        xp.append(xj)
        Pp.append(Pj)
    mix = sum(cbar[j] * lik[j] for j in range(r))
    xu, Pu = [], []
    for j in range(r):
        S = H @ Pp[j] @ H.T + R
        K = Pp[j] @ H.T @ np.linalg.inv(S)
        xu.append(xp[j] + K @ (z - H @ xp[j]))
        Pu.append((np.eye(4) - K @ H) @ Pp[j])
    post = np.array([cbar[j] * lik[j] for j in range(r)]) / mix
    xc = sum(post[j] * xu[j] for j in range(r))
    Pc = sum(post[j] * (Pu[j] + np.outer(xu[j] - xc, xu[j] - xc)) for j in range(r))
    return np.array(xp), np.array(Pp), cbar, math.log(mix), np.array(xu), np.array(Pu), post, xc, Pc


@pytest.mark.parametrize("sigmas", [(1.0, 10.0), (0.5, 3.0, 20.0)])
def test_batched_cycle_matches_the_textbook_form(sigmas):
    rng = np.random.default_rng(4)
    M, r, dt, tau = 7, len(sigmas), 2.5, 60.0
    models = imm.CVModelSet(sigmas, tau)
    xm, Pm, mu = random_tracks(rng, M, r)
    z = rng.normal(0, 500, (M, 2))
    R = np.array([[1e4, 2e3], [2e3, 2e4]])
    xp, Pp, mubar = models.predict_models(xm, Pm, mu, dt)
    ll = imm.mixture_loglik(mubar, imm.model_logliks(xp, Pp, z, R))
    xu, Pu, post = imm.update(xp, Pp, mubar, z, R)
    xc, Pc = imm.combine(xu, Pu, post)
    for m in range(M):
        ref = reference_step(xm[m], Pm[m], mu[m], sigmas, tau, dt, z[m], R)
        np.testing.assert_allclose(xp[m], ref[0], rtol=1e-10, atol=1e-6)
        np.testing.assert_allclose(Pp[m], ref[1], rtol=1e-9, atol=1e-6)
        np.testing.assert_allclose(mubar[m], ref[2], rtol=1e-12)
        assert ll[m] == pytest.approx(ref[3], rel=1e-10)
        np.testing.assert_allclose(xu[m], ref[4], rtol=1e-9, atol=1e-6)
        np.testing.assert_allclose(Pu[m], ref[5], rtol=1e-8, atol=1e-5)
        np.testing.assert_allclose(post[m], ref[6], rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(xc[m], ref[7], rtol=1e-9, atol=1e-6)
        np.testing.assert_allclose(Pc[m], ref[8], rtol=1e-8, atol=1e-5)


def test_identical_models_are_the_kalman_filter():
    rng = np.random.default_rng(5)
    xm, Pm, _ = random_tracks(rng, 5, 1)
    x, P = xm[:, 0], Pm[:, 0]
    models = imm.CVModelSet((10.0, 10.0), 100.0)
    xs, Ps, mu = np.repeat(xm, 2, 1), np.repeat(Pm, 2, 1), np.full((5, 2), 0.5)
    xp, Pp, mubar = models.predict_models(xs, Ps, mu, 1.0)
    kx, kP = kalman.predict(x, P, ConstantVelocity.F(1.0), ConstantVelocity(10.0).Q(1.0))
    np.testing.assert_allclose(imm.combine(xp, Pp, mubar)[0], kx, atol=1e-9)
    np.testing.assert_allclose(imm.combine(xp, Pp, mubar)[1], kP, rtol=1e-12, atol=1e-9)
    z = rng.normal(0, 500, (5, 2))
    R = np.eye(2) * 1e4
    ll = imm.mixture_loglik(mubar, imm.model_logliks(xp, Pp, z, R))
    np.testing.assert_allclose(ll, np.diag(kalman.innovation_loglik(kx, kP, z, R)[1]), rtol=1e-12)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), dt=st.floats(0.1, 30.0),
       tau=st.floats(1.0, 1000.0))
def test_probabilities_and_covariances_stay_valid(seed, dt, tau):
    rng = np.random.default_rng(seed)
    models = imm.CVModelSet((1.0, 10.0), tau)
    xm, Pm, mu = random_tracks(rng, 6, 2)
    xp, Pp, mubar = models.predict_models(xm, Pm, mu, dt)
    xu, Pu, post = imm.update(xp, Pp, mubar, rng.normal(0, 1e3, (6, 2)), np.eye(2) * 1e4)
    for p in (mubar, post):
        assert (p >= 0).all()
        np.testing.assert_allclose(p.sum(axis=1), 1.0, rtol=1e-12)
    for P in (imm.combine(xp, Pp, mubar)[1], imm.combine(xu, Pu, post)[1]):
        np.testing.assert_allclose(P, np.swapaxes(P, -1, -2), rtol=0, atol=1e-6)
        assert (np.linalg.eigvalsh(P) > 0).all()


def test_model_set_is_validated():
    with pytest.raises(ValueError, match="two models"):
        imm.CVModelSet((1.0,))
    with pytest.raises(ValueError, match="sigmas"):
        imm.CVModelSet((1.0, float("nan")))
    with pytest.raises(ValueError, match="mode_time"):
        imm.CVModelSet((1.0, 10.0), 0.0)
    pi = imm.CVModelSet((1.0, 10.0), 100.0).transition(1.0)
    np.testing.assert_allclose(pi.sum(axis=1), 1.0)
    assert pi[0, 0] == pytest.approx(math.exp(-0.01))


@pytest.mark.parametrize(("r", "per_row"), [(2, False), (2, True), (3, False), (4, True)])
def test_mixing_and_prediction_equal_the_einsum_forms_bit_for_bit(r, per_row):
    """The batched mixing (``Σ_i`` in model order, all models predicted at once) gives the
    same floats as the einsum formulas and the per-model loop it replaced."""
    rng = np.random.default_rng(r)
    m_rows = 40
    sigmas = tuple(float(s) for s in rng.uniform(0.5, 20.0, r))
    xm = rng.normal(0, 1000, (m_rows, r, 4))
    A = rng.normal(0, 30, (m_rows, r, 4, 4))
    Pm = A @ np.swapaxes(A, -1, -2) + np.eye(4)
    mu = rng.dirichlet(np.ones(r), m_rows)
    dt = rng.uniform(0.5, 12.0, m_rows) if per_row else 4.0
    model = imm.CVModelSet(sigmas, 100.0)
    xp, Pp, mubar = model.predict_models(xm, Pm, mu, dt)
    pi = model.transition(dt)
    pim = pi[None] if pi.ndim == 2 else pi
    want_mubar = mu @ pi if pi.ndim == 2 else np.einsum("mi,mij->mj", mu, pi)
    w = pim * mu[:, :, None] / np.maximum(want_mubar, 1e-300)[:, None, :]
    x0 = np.einsum("mij,mia->mja", w, xm)
    d = xm[:, :, None, :] - x0[:, None, :, :]
    P0 = np.einsum("mij,miab->mjab", w, Pm) + np.einsum("mij,mija,mijb->mjab", w, d, d)
    for j, s in enumerate(sigmas):
        x_j, P_j = cv_predict(x0[:, j], P0[:, j], dt, ConstantVelocity(s).Q(dt))
        assert np.array_equal(xp[:, j], x_j) and np.array_equal(Pp[:, j], P_j)
    assert np.array_equal(mubar, want_mubar)
    x, P = imm.combine(xp, Pp, mubar)
    dd = xp - x[:, None, :]
    want_P = (np.einsum("mj,mjab->mab", mubar, Pp)
              + np.einsum("mj,mja,mjb->mab", mubar, dd, dd))
    assert np.array_equal(x, np.einsum("mj,mja->ma", mubar, xp))
    assert np.array_equal(P, 0.5 * (want_P + np.swapaxes(want_P, -1, -2)))
