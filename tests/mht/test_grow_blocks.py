"""``grow_children`` updates the children block by block of rows
(``extend.UPDATE_BLOCK``): the leaves are bit for bit those of one pass, for the IMM and
the single constant-velocity model, with scans and with timed plots (``pair_pred``)."""

import numpy as np
import pytest
from frame_fixture import frame

from mhtrack.mht import extend
from mhtrack.mht.gating import Gated
from mhtrack.mht.tree import Leaves, one_point_state
from mhtrack.models.imm import CVModelSet
from mhtrack.models.motion import ConstantVelocity


@pytest.mark.parametrize("motion", [CVModelSet((1.0, 10.0)), ConstantVelocity(10.0)])
@pytest.mark.parametrize("timed", [False, True])
def test_blocks_give_the_leaves_of_one_pass(motion, timed, monkeypatch):
    rng = np.random.default_rng(5 + timed)
    n, m = 40, 30
    x, P = one_point_state(rng.uniform(-1e3, 1e3, (n, 2)), np.eye(2) * 100.0, 300.0)
    st = motion.new_states(x, P)
    i = np.arange(n)
    leaves = Leaves(st.x, st.P, rng.normal(size=n), rng.normal(size=n) + 1, i // 3, -1 + 0 * i,
                    0 * i, 1 + 0 * i, rng.integers(-1, 9, (n, 4)), np.zeros(n, bool), st.mu,
                    st.xm, st.Pm, i, -1 + 0 * i, np.zeros(n))
    pred = motion.predict(leaves.states(), 4.0)
    pairs = np.unique(np.c_[rng.integers(0, n, 120), rng.integers(0, m, 120)], axis=0)
    gated = Gated(pairs[:, 0], pairs[:, 1], np.zeros(len(pairs)), rng.normal(size=len(pairs)))
    children = extend.propose_children(leaves, gated, -1.0, rng.normal(size=len(pairs)))
    z = rng.uniform(-1e3, 1e3, (m, 2))
    R = np.eye(2) * 50.0
    rows = np.arange(100, 100 + m)
    t = rng.uniform(3.0, 4.0, m) if timed else None
    pair_pred = (motion.predict(leaves.states().take(gated.track), t[gated.plot])
                 if timed else None)
    f = frame(z, R, rows=rows, t=t, time=4.0)
    one = extend.grow_children(f, leaves, pred, children, motion=motion, pair_pred=pair_pred)
    monkeypatch.setattr(extend, "UPDATE_BLOCK", 7)
    got = extend.grow_children(f, leaves, pred, children, motion=motion, pair_pred=pair_pred)
    assert np.count_nonzero(children.plot >= 0) > 3 * 7  # several blocks, the last short
    for name, a in one.arrays().items():
        assert np.array_equal(got.arrays()[name], a, equal_nan=a.dtype.kind == "f"), name
