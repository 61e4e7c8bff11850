"""The IMM's per-row maximum and sum over models, done as whole-column operations, give the
very floats of NumPy's ``max(axis=1)`` / ``sum(axis=1)`` they replaced (the previous
formulas are kept here as the reference), for every model count."""

import numpy as np
import pytest

from mhtrack.models import imm


def _mixture_loglik_reference(mubar, ll):
    with np.errstate(divide="ignore"):
        a = np.log(mubar) + ll
    m = a.max(axis=1)
    return m + np.log(np.exp(a - m[:, None]).sum(axis=1))


def _posterior_reference(mubar, ll):
    with np.errstate(divide="ignore"):
        a = np.log(mubar) + ll
    a -= a.max(axis=1, keepdims=True)
    mu = np.exp(a)
    mu /= mu.sum(axis=1, keepdims=True)
    return mu


@pytest.mark.parametrize("r", [1, 2, 3, 4, 5, 6, 7, 8, 9, 12])
def test_row_max_and_sum_equal_numpy_reductions_bit_for_bit(r):
    rng = np.random.default_rng(r)
    a = rng.normal(0, 1, (5000, r)) * 10.0 ** rng.uniform(-8, 8, (5000, r))
    a[rng.random((5000, r)) < 0.05] = -np.inf
    assert imm._row_max(a).tobytes() == a.max(axis=1).tobytes()
    e = np.abs(a[:, ::-1]).copy()
    e[~np.isfinite(e)] = 0.0
    assert imm._row_sum(e).tobytes() == e.sum(axis=1).tobytes()


@pytest.mark.parametrize("r", [2, 3, 4])
def test_mixture_and_posterior_equal_the_reduction_forms_bit_for_bit(r):
    """``mixture_loglik`` and the posterior model probabilities of ``update`` against the
    forms with ``max``/``sum`` over axis 1, on random states, plots and probabilities
    (one model's probability 0 in some rows: ``ln 0 = −∞``)."""
    rng = np.random.default_rng(10 + r)
    K = 3000
    mubar = rng.dirichlet(np.ones(r), K)
    mubar[rng.random(K) < 0.1, 0] = 0.0
    xm = rng.normal(0, 500, (K, r, 4))
    A = rng.normal(0, 30, (K, r, 4, 4))
    Pm = A @ np.swapaxes(A, -1, -2) + np.eye(4) * 100
    Pm = 0.5 * (Pm + np.swapaxes(Pm, -1, -2))
    z = xm[:, 0, [0, 2]] + rng.normal(0, 300, (K, 2))
    R = np.array([[1e4, 50.0], [50.0, 2e4]])
    ll = imm.model_logliks(xm, Pm, z, R)
    assert (imm.mixture_loglik(mubar, ll).tobytes()
            == _mixture_loglik_reference(mubar, ll).tobytes())
    _, _, mu = imm.update(xm, Pm, mubar, z, R)
    assert mu.tobytes() == _posterior_reference(mubar, ll).tobytes()
