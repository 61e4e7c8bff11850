"""The shortcuts of a scan that every leaf was looked at alike (``Looks.uniform``), of a
gate asked for its pairs only (``loglik=False``) and of the run-length counts
(``segment_sizes``) give what the general paths give, bit for bit."""

import dataclasses

import numpy as np
import pytest
from frame_fixture import frame
from leaves_fixture import random_leaves
from test_gate_dense import _problem

from mhtrack.build import default_config, make_tracker
from mhtrack.kernels import segment_sizes
from mhtrack.mht import gating
from mhtrack.mht.coverage import Everywhere, Looks
from mhtrack.mht.gating import Gate, gate_sweep, gate_threshold
from mhtrack.mht.identity import Reported
from mhtrack.mht.timed import split_looked
from mhtrack.mht.tree import FIELDS, segment_starts
from mhtrack.models.imm import CVModelSet
from mhtrack.models.motion import ConstantVelocity
from mhtrack.scenario import preset, simulate


class _PerLeaf(Everywhere):
    """:class:`Everywhere` without the ``uniform`` shortcut: the per-leaf paths."""

    def detection(self, scan, x, P, time):
        looks = super().detection(scan, x, P, time)
        return Looks(looks.pd, looks.certain)


@pytest.mark.parametrize("tracker", ["mht-agmm", "mht"])
def test_uniform_looks_give_the_per_leaf_paths_stores(tracker):
    sc = preset("crossing")
    scans = list(simulate(sc, seed=2).plots.scans())[:30]
    cfg = default_config(sc)
    fast, slow = make_tracker(tracker, cfg), make_tracker(tracker, cfg)
    slow.coverage = _PerLeaf(fast.coverage.p_detection)
    for scan in scans:
        a, b = fast.step(scan), slow.step(scan)
        for f in dataclasses.fields(a):
            assert np.array_equal(getattr(a, f.name), getattr(b, f.name)), f.name
        for f in FIELDS:
            x, y = getattr(fast.leaves, f), getattr(slow.leaves, f)
            assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=True), f
    assert len(fast.leaves) > 0


def test_split_looked_every_leaf_returns_an_unattached_empty_store():
    lv = random_leaves(np.random.default_rng(1), 30)
    looks = Everywhere(0.9).detection(None, lv.x, lv.P, lv.time)
    assert looks.uniform == 0.9
    looked, same, idle = split_looked(lv, looks)
    assert looked is lv and same is looks and len(idle) == 0
    for f in FIELDS:  # the shapes and types of the store's rows, not a view of it
        a, b = getattr(idle, f), getattr(lv, f)
        assert a.shape[1:] == b.shape[1:] and a.dtype == b.dtype and a.base is None


@pytest.mark.parametrize("seed", range(12))
def test_gate_without_loglik_gives_the_same_pairs(seed):
    rng = np.random.default_rng(seed)
    M, N = int(rng.integers(2, 200)), int(rng.integers(2, 200))  # dense and sweep paths
    x, P, z, R = _problem(rng, M, N, bool(seed % 2))
    gamma = gate_threshold(0.999)
    full, bare = gate_sweep(x, P, z, R, gamma), gate_sweep(x, P, z, R, gamma, loglik=False)
    assert len(full) > 0 and bare.loglik is None
    for f in ("track", "plot", "d2"):
        assert np.array_equal(getattr(full, f), getattr(bare, f))
    shared = not seed % 2
    boxes = gating._sweep_boxes(x, P, z, R, shared, gamma)
    swept = gating._pairs_in_boxes(x, P, z, R, shared, gamma, boxes, loglik=False)
    assert swept.loglik is None and np.array_equal(swept.d2, full.d2)
    # the budget path of the stage, too
    lv = random_leaves(rng, M)
    f = frame(z, R, max_gated_pairs=max(1, M * N // 3))
    g = Gate(0.999).pairs(f, lv, x, P, loglik=False)
    h = Gate(0.999).pairs(f, lv, x, P)
    assert g.loglik is None and np.array_equal(g.track, h.track) and np.array_equal(g.d2, h.d2)


def test_which_motion_models_read_the_gate_loglik():
    assert ConstantVelocity().reads_gate_loglik
    imm = CVModelSet((1.0, 20.0))
    assert not imm.reads_gate_loglik
    assert "reads_gate_loglik" not in [f.name for f in dataclasses.fields(imm)]
    st = imm.new_states(np.zeros((3, 4)), np.tile(np.eye(4), (3, 1, 1)))
    e = np.zeros(0, np.int64)
    ll, post = imm.gating_scores(st, e, e, np.zeros((2, 2)), np.eye(2), None)
    assert ll.shape == (0,) and ll.dtype == float and post is None


@pytest.mark.parametrize("seed", range(30))
def test_segment_sizes_equal_the_differences_of_the_starts(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 60))
    starts = segment_starts(np.sort(rng.integers(0, 1 + n // 3, n)))
    got, want = segment_sizes(starts, n), np.diff(np.r_[starts, n])
    assert got.dtype == want.dtype and np.array_equal(got, want) and got.sum() == n


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("by_id", [False, True])
def test_reported_of_equals_the_masked_rows(seed, by_id):
    lv = random_leaves(np.random.default_rng(seed), 40)
    rep = lv.chosen & (lv.track >= 0)
    got = Reported.of(lv, by_id=by_id)
    assert np.array_equal(got.track, lv.track[rep])
    assert np.array_equal(got.window, lv.window[rep] if by_id else lv.window[rep, 1:])
