"""The in-place forms of the Kalman and IMM kernels (issue 18, the 1 000-target scene) give
bit-for-bit the floats of the expressions they replaced, written out here as they were."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.models import imm, kalman
from mhtrack.models.linalg2 import sym_det2


def _spd(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    a = rng.normal(size=(*shape, 4, 4))
    return a @ np.swapaxes(a, -1, -2) + np.eye(4)


def _mix_sum_ref(w: np.ndarray, a: np.ndarray) -> np.ndarray:
    out = w[:, 0] * a[:, 0]
    for i in range(1, w.shape[1]):
        out = out + w[:, i] * a[:, i]
    return out


def _predict_ref(x, P, dt, Q):
    xp, Pp = x.copy(), P.copy()
    if np.ndim(dt) == 0:
        xp[..., 0::2] += dt * x[..., 1::2]
        Pp[..., 0::2, :] += dt * Pp[..., 1::2, :]
        Pp[..., :, 0::2] += dt * Pp[..., :, 1::2]
    else:
        d = np.asarray(dt, float).reshape((-1,) + (1,) * (x.ndim - 1))
        xp[..., 0::2] += d * x[..., 1::2]
        Pp[..., 0::2, :] += d[..., None] * Pp[..., 1::2, :]
        Pp[..., :, 0::2] += d[..., None] * Pp[..., :, 1::2]
    Pp += Q
    return xp, 0.5 * (Pp + np.swapaxes(Pp, -1, -2))


def _update_ref(x, P, z, R):
    a0, a1 = P[:, :, 0], P[:, :, 2]
    s00, s01, s11 = a0[:, 0] + R[..., 0, 0], a0[:, 2] + R[..., 0, 1], a1[:, 2] + R[..., 1, 1]
    det = sym_det2(s00, s01, s11)
    i00, i01, i11 = s11 / det, -s01 / det, s00 / det
    k0 = a0 * i00[:, None] + a1 * i01[:, None]
    k1 = a0 * i01[:, None] + a1 * i11[:, None]
    nu = z - x[:, 0::2]
    xn = x + k0 * nu[:, :1] + k1 * nu[:, 1:]
    Pn = P - (k0[:, :, None] * a0[:, None, :] + k1[:, :, None] * a1[:, None, :])
    return xn, 0.5 * (Pn + np.swapaxes(Pn, -1, -2))


def _combine_ref(xm, Pm, mu):
    x = _mix_sum_ref(mu[..., None], xm)
    d = xm - x[:, None, :]
    P = _mix_sum_ref(mu[..., None, None], Pm) + _mix_sum_ref((mu[..., None] * d)[..., None],
                                                              d[..., None, :])
    return x, 0.5 * (P + np.swapaxes(P, -1, -2))


def _predict_models_ref(model, xm, Pm, mu, dt):
    pi = model.transition(dt)
    mubar, pim = (mu @ pi, pi[None]) if pi.ndim == 2 else (np.einsum("mi,mij->mj", mu, pi),
                                                           pi)
    w = pim * mu[:, :, None] / np.maximum(mubar, 1e-300)[:, None, :]
    x0 = _mix_sum_ref(w[..., None], xm[:, :, None, :])
    d = xm[:, :, None, :] - x0[:, None, :, :]
    wd = w[..., None] * d
    P0 = (_mix_sum_ref(w[..., None, None], Pm[:, :, None])
          + _mix_sum_ref(wd[..., :, None], d[..., None, :]))
    Q = (imm._process_noise(model.sigmas, float(dt)) if np.ndim(dt) == 0
         else np.stack([imm.ConstantVelocity(s).Q(dt) for s in model.sigmas], axis=-3))
    xp, Pp = _predict_ref(x0, P0, dt, Q)
    return xp, Pp, mubar


def _same(a: tuple, b: tuple) -> None:
    for u, v in zip(a, b, strict=True):
        assert u.shape == v.shape and np.array_equal(u, v)


@pytest.mark.parametrize("r", [2, 3])
@pytest.mark.parametrize("per_row", [False, True])
def test_imm_predict_and_combine_bit_identical(r: int, per_row: bool) -> None:
    rng = np.random.default_rng(r + 10 * per_row)
    m = 257
    model = imm.CVModelSet(tuple(float(s) for s in range(1, r + 1)), mode_time=30.0)
    xm, Pm = rng.normal(size=(m, r, 4)) * 100, _spd(rng, (m, r)) * 50
    mu = rng.dirichlet(np.ones(r), size=m)
    dt = rng.uniform(-1, 5, m) if per_row else 4.0
    _same(model.predict_models(xm, Pm, mu, dt), _predict_models_ref(model, xm, Pm, mu, dt))
    _same(imm.combine(xm, Pm, mu), _combine_ref(xm, Pm, mu))


@pytest.mark.parametrize("shared_R", [True, False])
def test_kalman_predict_update_bit_identical(shared_R: bool) -> None:
    rng = np.random.default_rng(3)
    k = 301
    x, P = rng.normal(size=(k, 4)) * 100, _spd(rng, (k,)) * 20
    Q = kalman_q = np.diag([1.0, 2.0, 3.0, 4.0])
    for overwrite in (False, True):
        P_in = P.copy()
        _same(kalman.predict_cv(x, P_in, 2.5, kalman_q, overwrite=overwrite),
              _predict_ref(x, P, 2.5, Q))
        if not overwrite:
            assert np.array_equal(P_in, P)  # the input is left alone
    z = rng.normal(size=(k, 2)) * 100
    R = np.array([[25.0, 3.0], [3.0, 36.0]]) if shared_R else _spd(rng, (k,))[:, :2, :2]
    _same(kalman.update_position(x, P, z, R), _update_ref(x, P, z, R))


@pytest.mark.parametrize("per_row", [False, True])
@pytest.mark.parametrize("block", [64, None])
def test_imm_predict_in_blocks_bit_identical(per_row: bool, block: int | None,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """Block by block (rows past ``BLOCK``, the last block short) or in one pass, the
    states are those of the one-pass formulas."""
    if block is not None:
        monkeypatch.setattr(imm, "BLOCK", block)
    rng = np.random.default_rng(7 + per_row)
    m = 2 * imm.BLOCK + 37
    model = imm.CVModelSet((1.0, 10.0), mode_time=50.0)
    xm, Pm = rng.normal(size=(m, 2, 4)) * 100, _spd(rng, (m, 2)) * 50
    mu = rng.dirichlet(np.ones(2), size=m)
    dt = rng.uniform(-1, 5, m) if per_row else 4.0
    x, P = rng.normal(size=(m, 4)), _spd(rng, (m,))
    got = model.predict(imm.States(x, P, xm, Pm, mu), dt)
    xp, Pp, mubar = _predict_models_ref(model, xm, Pm, mu, dt)
    _same((got.x, got.P, got.xm, got.Pm, got.mu), (*_combine_ref(xp, Pp, mubar), xp, Pp, mubar))


def _imm_update_ref(xm, Pm, mubar, z, R):
    """The former one-pass update: each model's Kalman update, posterior ``μ``."""
    K, r = mubar.shape
    ll = imm.model_logliks(xm, Pm, z, R)
    with np.errstate(divide="ignore"):
        a = np.log(mubar) + ll
    a -= a.max(axis=1)[:, None]
    mu = np.exp(a)
    mu /= mu.sum(axis=1)[:, None]
    Rr = R if R.ndim == 2 else np.repeat(R, r, axis=0)
    xn, Pn = _update_ref(xm.reshape(K * r, 4), Pm.reshape(K * r, 4, 4),
                         np.repeat(z, r, axis=0), Rr)
    return xn.reshape(K, r, 4), Pn.reshape(K, r, 4, 4), mu


@pytest.mark.parametrize("shared_R", [True, False])
@pytest.mark.parametrize("block", [64, None])
def test_imm_update_in_blocks_bit_identical(shared_R: bool, block: int | None,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    if block is not None:
        monkeypatch.setattr(imm, "BLOCK", block)
    rng = np.random.default_rng(11 + shared_R)
    k = 2 * imm.BLOCK + 45
    model = imm.CVModelSet((1.0, 10.0))
    xm, Pm = rng.normal(size=(k, 2, 4)) * 100, _spd(rng, (k, 2)) * 50
    mubar = rng.dirichlet(np.ones(2), size=k)
    z = rng.normal(size=(k, 2)) * 100
    R = np.array([[25.0, 3.0], [3.0, 36.0]]) if shared_R else _spd(rng, (k,))[:, :2, :2]
    got = model.update(imm.States(np.zeros((k, 4)), np.zeros((k, 4, 4)), xm, Pm, mubar), z, R)
    xn, Pn, mu = _imm_update_ref(xm, Pm, mubar, z, R)
    _same((got.x, got.P, got.xm, got.Pm, got.mu), (*_combine_ref(xn, Pn, mu), xn, Pn, mu))
