"""The dense gate (every track–plot pair as one matrix, for small problems) gives the sweep's
pairs with the very same floats: the tracker's outputs must not depend on which path a
scan's size takes."""

import numpy as np
import pytest

from mhtrack.mht import gating
from mhtrack.mht.gating import gate_threshold


def _problem(rng, M, N, per_plot_R):
    A = rng.normal(size=(M, 4, 4))
    P = (A @ A.transpose(0, 2, 1) + np.eye(4)) * rng.uniform(10, 3e4, (M, 1, 1))
    P = 0.5 * (P + P.transpose(0, 2, 1)) * float(rng.choice([0.1, 1.0, 30.0]))
    x = np.column_stack((rng.uniform(-4e3, 4e3, M), rng.normal(0, 100, M),
                         rng.uniform(-4e3, 4e3, M), rng.normal(0, 100, M)))
    z = rng.uniform(-4500, 4500, (N, 2))
    near = min(M, N) // 2  # plots near tracks: every problem has gated pairs
    z[:near] = x[:near, [0, 2]] + rng.normal(0, 50, (near, 2))
    if per_plot_R:
        B = rng.normal(size=(N, 2, 2)) * 80
        R = B @ B.transpose(0, 2, 1) + np.eye(2) * 100
    else:
        R = np.array([[1e4, 300.0], [300.0, 2e4]])
    return x, P, z, R


@pytest.mark.parametrize("seed", range(40))
def test_dense_gate_equals_sweep_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    M, N = int(rng.integers(2, 90)), int(rng.integers(2, 90))
    per_plot_R = bool(seed % 2)
    x, P, z, R = _problem(rng, M, N, per_plot_R)
    gamma = gate_threshold(float(rng.choice([0.99, 0.999, 0.99999])))
    sweep = gating._pairs_in_boxes(x, P, z, R, not per_plot_R, gamma,
                                   gating._sweep_boxes(x, P, z, R, not per_plot_R, gamma))
    dense = gating._dense_pairs(x, P, z, R, not per_plot_R, gamma)
    assert len(sweep) > 0
    for field in ("track", "plot", "d2", "loglik"):
        a, b = getattr(sweep, field), getattr(dense, field)
        assert a.dtype == b.dtype and a.shape == b.shape
        assert a.tobytes() == b.tobytes(), field


def test_gate_sweep_takes_the_dense_path_only_for_small_problems(monkeypatch):
    """Above :data:`DENSE_MAX_PAIRS` pairs the sweep runs; at or below, the matrix."""
    rng = np.random.default_rng(1)
    x, P, z, R = _problem(rng, 20, 30, False)
    called = []
    monkeypatch.setattr(gating, "_dense_pairs",
                        lambda *a: called.append(1) or gating.Gated(*[np.zeros(0)] * 4))
    monkeypatch.setattr(gating, "DENSE_MAX_PAIRS", 600)
    gating.gate_sweep(x, P, z, R, 13.8)
    assert called == [1]
    monkeypatch.setattr(gating, "DENSE_MAX_PAIRS", 599)
    assert len(gating.gate_sweep(x, P, z, R, 13.8)) > 0 and called == [1]
