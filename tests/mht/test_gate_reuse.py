"""The gate's per-pair posterior model probabilities (``MotionModel.gating_scores``) are the
very floats the IMM update computes for the pair, so ``grow_children`` given them grows
bit for bit the leaves it grows computing them itself (IMM and single model, shared and
per-plot ``R``, scans and timed plots, one block and several)."""

import numpy as np
import pytest
from frame_fixture import frame

from mhtrack.mht import extend
from mhtrack.mht.coverage import Looks
from mhtrack.mht.gating import Gate
from mhtrack.mht.timed import gate_looked
from mhtrack.mht.tree import Leaves, one_point_state
from mhtrack.models import imm
from mhtrack.models.imm import CVModelSet
from mhtrack.models.motion import ConstantVelocity


def _leaves(motion, rng, n):
    x, P = one_point_state(rng.uniform(-1e3, 1e3, (n, 2)), np.eye(2) * 2e4, 300.0)
    st = motion.new_states(x, P)
    if motion.n_models:  # unequal model probabilities, one of them 0 in some rows
        mu = rng.dirichlet(np.ones(motion.n_models), n)
        mu[rng.random(n) < 0.2, 0] = 0.0
        st = type(st)(st.x, st.P, st.xm + rng.normal(0, 30, st.xm.shape), st.Pm, mu)
    i = np.arange(n)
    return Leaves(st.x, st.P, rng.normal(size=n), rng.normal(size=n) + 1, i // 3, -1 + 0 * i,
                  0 * i, 1 + 0 * i, rng.integers(-1, 9, (n, 4)), np.zeros(n, bool), st.mu,
                  st.xm, st.Pm, i, -1 + 0 * i, np.zeros(n))


@pytest.mark.parametrize("motion", [CVModelSet((1.0, 10.0)), CVModelSet((0.5, 5.0, 30.0)),
                                    ConstantVelocity(10.0)])
@pytest.mark.parametrize("timed", [False, True])
@pytest.mark.parametrize("shared_R", [True, False])
@pytest.mark.parametrize("block", [None, 5])
def test_grow_with_the_gates_posterior_equals_grow_without(motion, timed, shared_R, block,
                                                            monkeypatch):
    rng = np.random.default_rng(17 + 2 * timed + shared_R)
    n, m = 50, 40
    leaves = _leaves(motion, rng, n)
    pred = motion.predict(leaves.states(), 4.0)
    z = rng.uniform(-1e3, 1e3, (m, 2))
    R = (np.array([[900.0, 40.0], [40.0, 1600.0]]) if shared_R
         else np.array([[900.0, 40.0], [40.0, 1600.0]]) * rng.uniform(0.5, 2, (m, 1, 1)))
    t = rng.uniform(3.0, 4.0, m) if timed else None
    f = frame(z, R, rows=np.arange(100, 100 + m), t=t, time=4.0, max_gated_pairs=10**6)
    gated, pair_pred = gate_looked(f, Gate(0.9999), leaves, pred,
                                   looks=Looks(np.ones(n), np.ones(n, bool)), motion=motion)
    assert len(gated) > 30
    assert (gated.posterior is None) == (motion.n_models == 0)
    children = extend.propose_children(leaves, gated, -1.0, rng.normal(size=len(gated)))
    keep = np.sort(rng.choice(len(children), len(children) // 2, replace=False))
    children = children.take(keep)  # pruned: the pairs left are not all, nor in a row
    if block is not None:
        monkeypatch.setattr(extend, "UPDATE_BLOCK", block)
    plain = extend.grow_children(f, leaves, pred, children, motion=motion, pair_pred=pair_pred)
    reused = extend.grow_children(f, leaves, pred, children, motion=motion, pair_pred=pair_pred,
                                  posterior=gated.posterior)
    for name, a in plain.arrays().items():
        assert a.tobytes() == reused.arrays()[name].tobytes(), name


def test_gating_scores_are_the_mixture_and_the_updates_posterior():
    """Against the separate forms: ``mixture_loglik`` of the model log-likelihoods, and
    ``update``'s own posterior of each pair."""
    rng = np.random.default_rng(3)
    motion = CVModelSet((1.0, 10.0))
    leaves = _leaves(motion, rng, 30)
    pred = motion.predict(leaves.states(), 4.0)
    track, plot = rng.integers(0, 30, 200), rng.integers(0, 20, 200)
    z = rng.uniform(-1e3, 1e3, (20, 2))
    R = np.eye(2) * 900.0
    lg, post = motion.gating_scores(pred, track, plot, z, R, np.zeros(200))
    st = pred.take(track)
    ll = imm.model_logliks(st.xm, st.Pm, z[plot], R)
    assert lg.tobytes() == imm.mixture_loglik(st.mu, ll).tobytes()
    assert lg.tobytes() == motion.gating_loglik(pred, track, plot, z, R, lg).tobytes()
    mu = post.probabilities()
    assert mu.tobytes() == imm.update(st.xm, st.Pm, st.mu, z[plot], R)[2].tobytes()
    np.testing.assert_allclose(mu.sum(axis=1), 1.0)
    rows = np.array([5, 0, 199, 5])
    assert post[rows].probabilities().tobytes() == mu[rows].tobytes()
    assert post[3:9].probabilities().tobytes() == mu[3:9].tobytes()
