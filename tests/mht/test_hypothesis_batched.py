"""The batched solve of all small clashing clusters chooses exactly the leaves the
per-cluster solver (:func:`solve_exact` on each cluster alone) chooses, ties included."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.mht import hypothesis as hyp_mod
from mhtrack.mht.clustering import cluster_trees, plot_keys
from mhtrack.mht.hypothesis import best_hypothesis, solve_exact


def _per_cluster(score, tree, window, by_id):
    """Reference: each cluster alone — its trees' best leaves (highest score, then lowest
    index) when their plots are distinct, else :func:`solve_exact` on its members."""
    cand = np.flatnonzero(score > 0)
    if cand.size == 0:
        return np.zeros(0, np.int64)
    s, t, w = score[cand], tree[cand], window[cand]
    tree_index, tree_cluster = cluster_trees(t, w, by_id=by_id)
    leaf_cluster = tree_cluster[tree_index]
    chosen = []
    for c in range(int(tree_cluster.max()) + 1):
        members = np.flatnonzero(leaf_cluster == c)
        best = [min(members[tree_index[members] == k], key=lambda i: (-s[i], i))
                for k in np.unique(tree_index[members])]
        _, key = plot_keys(w[best], by_id=by_id)
        if np.unique(key).size == key.size:
            chosen.extend(best)
        else:
            pick, _ = solve_exact(s[members], tree_index[members], w[members], by_id=by_id)
            chosen.extend(members[pick].tolist())
    return np.sort(cand[np.asarray(chosen, np.int64)])


def _problem(seed, n_trees, max_leaves, n_cols, n_plots, ties):
    """Random leaves, scores from a small set (ties) or continuous; many clusters when
    plots are many, wide windows so that one cluster may have more than 63 plots."""
    rng = np.random.default_rng(seed)
    sizes = rng.integers(1, max_leaves + 1, n_trees)
    tree = np.repeat(rng.permutation(n_trees) * 5 + 2, sizes)
    window = rng.integers(-1, n_plots, (tree.size, n_cols))
    window[rng.random(window.shape) < 0.4] = -1
    if ties:
        score = rng.choice([-1.0, 0.0, 1.0, 2.0, 2.0, 3.0], tree.size)
    else:
        score = np.round(rng.normal(0.5, 2.0, tree.size), 2)
    return score, tree, window


@settings(max_examples=400, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_trees=st.integers(1, 12),
    max_leaves=st.integers(1, 6),
    n_cols=st.integers(1, 30),
    n_plots=st.integers(1, 120),
    ties=st.booleans(),
    by_id=st.booleans(),
)
def test_batched_choice_equals_per_cluster_solver(seed, n_trees, max_leaves, n_cols,
                                                  n_plots, ties, by_id):
    score, tree, window = _problem(seed, n_trees, max_leaves, n_cols, n_plots, ties)
    got = best_hypothesis(score, tree, window, by_id=by_id)
    assert np.array_equal(got.leaves, _per_cluster(score, tree, window, by_id))


def test_a_clash_on_a_plot_ranked_past_63_is_seen():
    """Two trees, each leaf using 71 plots of its own; leaves 0 and 3 share only their
    plot in the last column, whose key ranks past 63 (Python-int masks)."""
    window = np.arange(4)[:, None] * 100 + np.arange(71)
    window[3, 70] = window[0, 70]
    tree = np.array([1, 1, 2, 2])
    score = np.array([1.0, 0.5, 1.0, 3.0])
    got = best_hypothesis(score, tree, window)
    assert got.leaves.tolist() == [1, 3] and got.n_searched == 1
    assert np.array_equal(got.leaves, _per_cluster(score, tree, window, False))


@pytest.mark.parametrize("seed", range(20))
def test_node_limited_clusters_go_to_milp_as_before(seed, monkeypatch):
    """With a tiny node budget the searches hand over to ``milp``: same choice as the
    per-cluster path, and an exact optimum either way."""
    monkeypatch.setattr(hyp_mod, "BNB_NODE_LIMIT", 3)
    score, tree, window = _problem(seed, 8, 4, 3, 4, True)
    got = best_hypothesis(score, tree, window)
    assert np.array_equal(got.leaves, _per_cluster(score, tree, window, False))
