"""The fast paths of the MHT (``mhtrack.models.kalman``, ``mhtrack.mht.gating``) agree
with the general matrix forms they shortcut (``tests/reference/kalman_reference.py``)."""

import kalman_reference as ref
import numpy as np
from frame_fixture import frame
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.mht.gating import gate_candidate_counts, gate_sweep, gate_threshold
from mhtrack.models import kalman
from mhtrack.models.motion import ConstantVelocity


def _tracks(rng, M, scale=1.0):
    A = rng.normal(size=(M, 4, 4))
    P = (A @ A.transpose(0, 2, 1) + np.eye(4)) * rng.uniform(10, 3e4, (M, 1, 1)) * scale
    x = np.column_stack(
        (rng.uniform(-4e3, 4e3, M), rng.normal(0, 100, M), rng.uniform(-4e3, 4e3, M),
         rng.normal(0, 100, M))
    )
    return x, 0.5 * (P + P.transpose(0, 2, 1))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.1, 10.0))
def test_predict_cv_equals_predict(seed, dt):
    rng = np.random.default_rng(seed)
    x, P = _tracks(rng, 9)
    m = ConstantVelocity(10.0)
    xa, Pa = ref.predict(x, P, m.F(dt), m.Q(dt))
    xb, Pb = kalman.predict_cv(x, P, dt, m.Q(dt))
    np.testing.assert_allclose(xb, xa, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(Pb, Pa, rtol=1e-10, atol=1e-6)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_update_position_equals_update(seed, per_pair_R):
    rng = np.random.default_rng(seed)
    x, P = _tracks(rng, 7)
    z = x[:, [0, 2]] + rng.normal(0, 200, (7, 2))
    if per_pair_R:
        B = rng.normal(size=(7, 2, 2)) * 50
        R = B @ B.transpose(0, 2, 1) + np.eye(2) * 100
    else:
        R = np.array([[1e4, 300.0], [300.0, 2e4]])
    xa, Pa = ref.update(x, P, z, R)
    xb, Pb = kalman.update_position(x, P, z, R)
    np.testing.assert_allclose(xb, xa, rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(Pb, Pa, rtol=1e-7, atol=1e-6 * np.abs(Pa).max())
    assert np.all(np.linalg.eigvalsh(Pb) > 0)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 40), st.integers(0, 60), st.booleans())
def test_gate_sweep_equals_gate(seed, M, N, per_plot_R):
    rng = np.random.default_rng(seed)
    x, P = _tracks(rng, M, scale=float(rng.choice([0.1, 1.0, 30.0])))
    z = rng.uniform(-4500, 4500, (N, 2))
    if per_plot_R:
        B = rng.normal(size=(N, 2, 2)) * 80
        R = B @ B.transpose(0, 2, 1) + np.eye(2) * 100
    else:
        R = np.eye(2) * 1e4
    gamma = gate_threshold(0.999)
    a = ref.gate(x, P, z, R, gamma)
    b = gate_sweep(x, P, z, R, gamma)
    assert np.array_equal(a.track, b.track)
    assert np.array_equal(a.plot, b.plot)
    np.testing.assert_allclose(b.d2, a.d2, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(b.loglik, a.loglik, rtol=1e-12, atol=1e-12)
    counts = gate_candidate_counts(x, P, z, R, gamma)
    assert np.all(np.bincount(b.track, minlength=M) <= counts)


def test_gate_sweep_with_many_plots_matches_gate():
    rng = np.random.default_rng(0)
    x, P = _tracks(rng, 300)
    z = rng.uniform(-4000, 4000, (5000, 2))
    R = np.eye(2) * 1e4
    a = ref.gate(x, P, z, R, 13.8)
    b = gate_sweep(x, P, z, R, 13.8)
    assert len(a) > 1000
    assert np.array_equal(a.track, b.track) and np.array_equal(a.plot, b.plot)


class _Leaves:
    """What :meth:`Gate.pairs` reads of the leaves: their number, scores and tracks."""

    def __init__(self, score, track):
        self.score, self.track = score, track

    def __len__(self):
        return len(self.score)


def test_gate_within_budget_gates_confirmed_then_best_leaves():
    """With a budget below the candidates, the leaves of confirmed tracks and then the
    best-scoring ones are gated (whole leaves, in that order, while their candidates fit);
    their pairs are the reference gate's, the others get none."""
    from mhtrack.mht.gating import Gate

    rng = np.random.default_rng(5)
    M = 120
    x, P = _tracks(rng, M)
    z = rng.uniform(-4000, 4000, (400, 2))
    R = np.eye(2) * 1e4
    leaves = _Leaves(rng.normal(size=M), np.where(rng.random(M) < 0.2, 7, -1))
    counts = gate_candidate_counts(x, P, z, R, gate_threshold(0.999))
    for budget in (10**9, int(counts.sum()), int(counts.sum()) // 3):
        gate = Gate(0.999)
        f = frame(z, R, max_gated_pairs=budget)
        g = gate.pairs(f, leaves, x, P)
        order = np.lexsort((-leaves.score, leaves.track < 0))
        sel = np.sort(order[np.cumsum(counts[order]) <= budget])
        want = ref.gate(x[sel], P[sel], z, R, gate.gamma)
        assert np.array_equal(g.track, sel[want.track]) and np.array_equal(g.plot, want.plot)
        np.testing.assert_allclose(g.loglik, want.loglik, rtol=1e-12, atol=1e-12)
        assert f.caps.get("max_gated_pairs", 0) == M - sel.size
        assert (sel.size < M) == (budget < counts.sum())
