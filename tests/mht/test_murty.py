"""N best global hypotheses (Murty's partitioning) and track probabilities, against
brute-force enumeration of every hypothesis of small random clusters."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.build import default_config, make_tracker
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.hypothesis import best_hypothesis
from mhtrack.mht.merging import merge_keep
from mhtrack.mht.murty import n_best_hypotheses
from mhtrack.mht.track_probability import (
    hypothesis_probabilities,
    leaf_probabilities,
    tree_probabilities,
)
from mhtrack.scenario import preset, simulate


def _problem(seed: int, n_trees: int, max_leaves: int, n_plots: int, ties: bool):
    rng = np.random.default_rng(seed)
    sizes = rng.integers(1, max_leaves + 1, n_trees)
    tree = np.repeat(np.arange(n_trees) * 5 + 2, sizes)
    n = tree.size
    window = rng.integers(-1, n_plots, (n, 3))
    if ties:  # many equal totals
        score = rng.choice([-1.0, 0.0, 0.5, 1.0, 1.5], n)
    else:
        score = np.round(rng.normal(0.5, 2.0, n), 3)
    return score, tree, window


def brute_force_ranking(score, tree, window):
    """Every hypothesis over the positive leaves (one leaf or none per tree, no plot used
    twice) sorted by (−total, sorted leaf indices), totals by math.fsum."""
    pos = np.flatnonzero(score > 0)
    trees = sorted(set(tree[pos].tolist()))
    options = [[None, *pos[tree[pos] == t].tolist()] for t in trees]
    out = []
    for combo in itertools.product(*options):
        sel = tuple(sorted(i for i in combo if i is not None))
        used = [(c, p) for i in sel for c, p in enumerate(window[i].tolist()) if p >= 0]
        if len(used) == len(set(used)):
            out.append((sel, math.fsum(score[i] for i in sel)))
    out.sort(key=lambda h: (-h[1], h[0]))
    return out


def brute_force_probability(score, tree, window, n):
    ranked = brute_force_ranking(score, tree, window)[:n]
    w = [math.exp(t - ranked[0][1]) for _, t in ranked]
    p = np.zeros(score.size)
    for (sel, _), wi in zip(ranked, w, strict=True):
        for i in sel:
            p[i] += wi / sum(w)
    return p


@settings(max_examples=300, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_trees=st.integers(1, 5),
    max_leaves=st.integers(1, 4),
    n_plots=st.integers(1, 5),
    ties=st.booleans(),
    n=st.integers(1, 12),
)
def test_murty_n_best_equals_brute_force(seed, n_trees, max_leaves, n_plots, ties, n):
    score, tree, window = _problem(seed, n_trees, max_leaves, n_plots, ties)
    ref = brute_force_ranking(score, tree, window)
    got, complete = n_best_hypotheses(score, tree, window, n)
    assert complete
    # the same hypotheses in the same order, ties included (order documented in murty)
    assert [sel for sel, _ in got] == [sel for sel, _ in ref[:n]]
    assert [t for _, t in got] == [t for _, t in ref[:n]]
    # probabilities against the brute-force formula
    p = leaf_probabilities(got, score.size)
    assert p == pytest.approx(brute_force_probability(score, tree, window, n), abs=1e-12)


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 8), ties=st.booleans())
def test_murty_best_hypothesis_probabilities_per_cluster(seed, n, ties):
    """best_hypothesis(n_best) splits into clusters; each cluster's probabilities are its
    own N best's (brute force per cluster, the clusters found independently here)."""
    score, tree, window = _problem(seed, 6, 3, 8, ties)
    hyp = best_hypothesis(score, tree, window, n_best=n)
    one = best_hypothesis(score, tree, window)
    # the reported best is as good (the same unless another hypothesis ties with it)
    assert hyp.total == pytest.approx(one.total, abs=1e-9)
    if n == 1:
        assert np.array_equal(hyp.leaves, one.leaves)
        assert np.array_equal(np.flatnonzero(hyp.probability), one.leaves)
        assert (hyp.probability[one.leaves] == 1).all()
        return
    # clusters of trees by shared (column, plot) among positive leaves: union–find
    pos = np.flatnonzero(score > 0)
    parent = {t: t for t in set(tree[pos].tolist())}

    def find(t):
        while parent[t] != t:
            t = parent[t]
        return t

    seen = {}
    for i in pos.tolist():
        for c, p in enumerate(window[i].tolist()):
            if p >= 0:
                if (c, p) in seen:
                    parent[find(tree[i])] = find(seen[(c, p)])
                else:
                    seen[(c, p)] = tree[i]
    expected = np.zeros(score.size)
    for root in {find(t) for t in parent}:
        members = np.flatnonzero(np.isin(tree, [t for t in parent if find(t) == root]))
        sub = brute_force_probability(score[members], tree[members], window[members], n)
        expected[members] = sub
        # the cluster's choice is its first hypothesis in the documented order
        first = brute_force_ranking(score[members], tree[members], window[members])[0][0]
        assert np.array_equal(members[list(first)], np.intersect1d(hyp.leaves, members))
    assert hyp.probability == pytest.approx(expected, abs=1e-12)


def test_murty_ties_are_ranked_by_leaf_indices():
    # two trees, each with two equal leaves on distinct plots: 9 hypotheses, totals
    # 2 (×4), 1 (×4), 0 (×1); equal totals in ascending tuple order
    score = np.array([1.0, 1.0, 1.0, 1.0])
    tree = np.array([0, 0, 1, 1])
    window = np.array([[-1, 5], [-1, 6], [-1, 7], [-1, 8]])
    got, complete = n_best_hypotheses(score, tree, window, 20)
    assert complete
    assert [sel for sel, _ in got] == [(0, 2), (0, 3), (1, 2), (1, 3),
                                       (0,), (1,), (2,), (3,), ()]
    p = leaf_probabilities(got, 4)
    assert p == pytest.approx(np.full(4, (2 * math.e**2 + math.e) / (4 * math.e**2
                                                                   + 4 * math.e + 1)))


def test_hand_worked_probabilities():
    # one tree with one leaf of score ln 3: hypotheses {leaf} (weight 3) and {} (1)
    score = np.array([math.log(3.0)])
    got, _ = n_best_hypotheses(score, np.array([0]), np.array([[-1, 4]]), 5)
    assert [sel for sel, _ in got] == [(0,), ()]
    assert leaf_probabilities(got, 1) == pytest.approx([0.75])
    assert hypothesis_probabilities([0.0, 0.0]) == pytest.approx([0.5, 0.5])
    assert tree_probabilities(np.array([3, 3, 4]), np.array([0.25, 0.5, 0.1])) == {
        3: 0.75, 4: 0.1}


def test_murty_node_limit_stops_with_what_it_found():
    score, tree, window = _problem(3, 14, 4, 4, False)
    got, complete = n_best_hypotheses(score, tree, window, 50, node_limit=20)
    assert not complete
    ref = brute_force_ranking(score, tree, window)
    assert [s for s, _ in got] == [s for s, _ in ref[: len(got)]]


def test_merge_keep_keeps_one_of_each_duplicate_group():
    window = np.array([[1, 2, 3], [9, 2, 3], [1, 2, 3], [4, -1, -1], [5, -1, -1],
                       [1, 2, 4]])
    score = np.array([1.0, 5.0, 2.0, 0.0, 0.0, 9.0])
    chosen = np.array([False, False, True, False, False, False])
    confirmed = np.zeros(6, bool)
    keep = merge_keep(window, chosen, confirmed, score, frames=2)
    # rows 0, 1, 2 share (2, 3): the chosen row 2 stays; rows 3, 4 share only misses
    assert keep.tolist() == [False, False, True, True, True, True]
    keep = merge_keep(window, np.zeros(6, bool), confirmed, score, frames=2)
    assert keep.tolist() == [False, True, False, True, True, True]
    assert merge_keep(window, chosen, confirmed, score, frames=0).all()
    assert merge_keep(window, chosen, confirmed, score, frames=3).tolist() == [
        False, True, True, True, True, True]


def _run(config):
    sim = simulate(preset("crossing"), seed=3)
    trk = make_tracker("mht-agmm", config)
    return trk.run(sim.plots)


def test_murty_n_best_without_pruning_reports_the_same_tracks():
    sim = simulate(preset("crossing"), seed=3)
    base = default_config(sim.scenario)
    a = _run(base)
    b = _run(MHTConfig(**{**base.__dict__, "n_best": 10}))
    assert a.track_id.tolist() == b.track_id.tolist()
    assert np.array_equal(a.x, b.x) and np.array_equal(a.score, b.score)


def test_config_reads_the_removed_time_limit_and_checks_the_new_fields():
    cfg = MHTConfig.from_json('{"milp_time_limit": 0.5, "n_best": 3}')
    assert cfg.n_best == 3 and cfg.milp_node_limit == MHTConfig().milp_node_limit
    for bad in ({"n_best": 0}, {"prune_probability": 1.0}, {"merge_frames": 5},
                {"milp_node_limit": 0}):
        with pytest.raises(ValueError):
            MHTConfig(**bad)
    assert isinstance(MHTTracker(MHTConfig(n_best=2)), MHTTracker)
