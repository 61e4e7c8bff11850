"""N-scan pruning, score-drop pruning, SPRT deletion, caps and clustering, by hand."""

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from mhtrack.mht import (
    best_hypothesis,
    cap_leaves,
    cap_leaves_per_tree,
    cap_trees,
    cluster_trees,
    n_scan_keep,
    score_drop_keep,
    sprt_keep,
)

# N = 2: window columns are scans k−2, k−1, k; column 0 is the scan being decided.
# Tree 10 (a track) branched at k−2 on plots 7 / 8 / miss; tree 20 is a younger tree that
# used plot 8 at k−2; tree 30 competes for nothing at k−2 and is not in the hypothesis.
TREE = np.array([10, 10, 10, 10, 10, 20, 20, 30, 30])
WINDOW = np.array(
    [
        [7, 1, 2],  # 0  tree 10: plot 7 at k−2 — the chosen branch
        [7, -1, 3],  # 1  tree 10: same plot at k−2, differs later — kept
        [8, 1, 2],  # 2  tree 10: plot 8 at k−2 — pruned (decision at k−2 is plot 7)
        [-1, 1, 4],  # 3  tree 10: miss at k−2 — pruned
        [8, 5, -1],  # 4  tree 10: plot 8 again — pruned
        [8, 9, 6],  # 5  tree 20: plot 8 at k−2, chosen for tree 20
        [-1, 9, 4],  # 6  tree 20: miss at k−2 — pruned
        [7, 11, 12],  # 7 tree 30: plot 7 at k−2 is used by tree 10's choice — pruned
        [-1, 11, 13],  # 8 tree 30: not in the hypothesis, no clash at k−2 — kept
    ]
)


def test_n_scan_pruning_by_hand():
    chosen = np.array([0, 5])
    keep = n_scan_keep(TREE, WINDOW[:, 0], chosen)
    assert np.flatnonzero(keep).tolist() == [0, 1, 5, 8]


def test_n_scan_pruning_after_the_best_hypothesis():
    score = np.array([9.0, 5.0, 8.0, 1.0, 2.0, 4.0, 3.0, 6.0, -1.0])
    hyp = best_hypothesis(score, TREE, WINDOW)
    # Leaf 0 (9) is the best single leaf but clashes with leaf 7 on plot 7 at k−2; by hand:
    # 0 + 5 = 13, 0 + 6 = 12, 2 + 6 + 7 = 8 + 3 + 6 = 17 (plots 8,1,2 / 9,4 / 7,11,12 are
    # disjoint), every other compatible set is lower.
    assert hyp.leaves.tolist() == [2, 6, 7]
    assert hyp.total == 17.0
    keep = n_scan_keep(TREE, WINDOW[:, 0], hyp.leaves)
    # tree 10 decided plot 8 at k−2: keeps leaves 2, 4; tree 20 decided "miss": keeps 6;
    # tree 30 decided plot 7: keeps 7; leaf 5 (plot 8 taken by tree 10) is pruned.
    assert np.flatnonzero(keep).tolist() == [2, 4, 6, 7]


def test_sprt_keep_is_a_drop_from_the_peak():
    score = np.array([5.0, -3.0, 0.0, 10.0])
    peak = np.array([5.0, 6.0, 9.2, 19.2])
    keep = sprt_keep(score, peak, -9.2)
    # drops 0, −9, −9.2 (deleted: ≤ threshold), −9.2 (deleted)
    assert keep.tolist() == [True, True, False, False]


def test_score_drop_keep_within_each_tree():
    tree = np.array([0, 0, 0, 1, 1])
    score = np.array([20.0, 8.0, 7.9, -5.0, -17.5])
    assert score_drop_keep(tree, score, 12.0).tolist() == [True, True, False, True, False]


def test_cap_leaves_per_tree_keeps_the_best():
    tree = np.array([0, 0, 0, 0, 1, 1, 2])
    score = np.array([1.0, 4.0, 3.0, 4.0, 0.0, 1.0, 5.0])
    keep, cut = cap_leaves_per_tree(tree, score, 2)
    # tree 0: the two 4.0s (ties → lower index first); tree 1 and 2 are within the cap
    assert keep.tolist() == [False, True, False, True, True, True, True]
    assert cut == 2
    keep, cut = cap_leaves_per_tree(tree, score, 4)
    assert keep.all() and cut == 0


def test_cap_leaves_prefers_confirmed_then_score():
    score = np.array([1.0, 9.0, 2.0, 8.0])
    confirmed = np.array([True, False, True, False])
    keep, cut = cap_leaves(score, confirmed, 3)
    assert keep.tolist() == [True, True, True, False] and cut == 1


def test_cap_trees_prefers_protected_then_best_score():
    tree = np.array([0, 0, 1, 2, 2, 3])
    score = np.array([1.0, 2.0, 9.0, 5.0, 0.0, 7.0])
    protected = np.array([False, True, False, False, False, False])
    keep, cut = cap_trees(tree, score, protected, 2)
    # tree 0 protected; then the best of 1 (9), 2 (5), 3 (7): tree 1
    assert keep.tolist() == [True, True, True, False, False, False]
    assert cut == 2


def test_clusters_by_hand():
    tree = np.array([5, 5, 6, 7, 8, 8, 9])
    window = np.array(
        [
            [1, -1],  # tree 5 uses plot 1 at column 0
            [-1, 4],  # tree 5 uses plot 4 at column 1
            [-1, 4],  # tree 6 also uses plot 4 at column 1 → same cluster as 5
            [4, -1],  # tree 7 uses plot 4 at column 0: another scan, no link
            [-1, 2],  # tree 8 …
            [1, -1],  # … and plot 1 at column 0 → joins 5 and 6
            [-1, -1],  # tree 9: no plot in the window
        ]
    )
    tree_index, cluster = cluster_trees(tree, window)
    assert tree_index.tolist() == [0, 0, 1, 2, 3, 3, 4]
    assert cluster.tolist() == [0, 0, 1, 0, 2]


def test_clusters_match_scipy_connected_components():
    rng = np.random.default_rng(4)
    for _ in range(200):
        n = int(rng.integers(1, 60))
        tree = np.sort(rng.integers(0, 20, n))
        window = rng.integers(-1, 12, (n, 3))
        ti, cl = cluster_trees(tree, window)
        T = cl.size
        cols = np.nonzero(window >= 0)
        key = cols[1] * 100 + window[cols]
        _, key = np.unique(key, return_inverse=True)
        g = coo_matrix((np.ones(key.size), (ti[cols[0]], T + key)), shape=(T + 400, T + 400))
        ref = connected_components(g, directed=False)[1][:T]
        # same partition
        assert len(set(zip(cl.tolist(), ref.tolist(), strict=True))) == len(set(ref.tolist()))
        assert len(set(cl.tolist())) == len(set(ref.tolist()))
        # labels numbered by first appearance
        _, first = np.unique(cl, return_index=True)
        assert np.all(np.diff(first) > 0)


def test_tentative_keep_is_walds_absolute_lower_threshold():
    from mhtrack.mht.sprt import tentative_keep

    score = np.array([-10.0, -9.0, -10.0, 3.0])
    tentative = np.array([True, True, False, True])
    # ln(β/(1−α)) with α = 0.01, β = 1e−4: −9.2: only the tentative leaf at −10 goes;
    # the confirmed leaf at −10 is judged by its drop from the peak instead.
    assert tentative_keep(score, tentative, np.log(1e-4 / 0.99)).tolist() == [
        False, True, True, True]


def test_hopeless_births_are_not_started():
    """κ̂ = 1e−2 per m² (a dense clutter clump): birth score ln(1e−7·0.9/1e−2) ≈ −11.6,
    below the deletion threshold −9.2, so no tree starts; at κ̂ = 1e−9 all three start."""
    from mhtrack.clutter import KnownClutter
    from mhtrack.mht import MHTConfig, MHTTracker
    from mhtrack.records import Scan

    scan = Scan.from_positions(1, 1.0, np.array([[0.0, 0.0], [10.0, 5.0], [3.0, -4.0]]))
    dense = MHTTracker(MHTConfig(), KnownClutter(1e-2))
    dense.step(scan)
    assert len(dense.leaves) == 0
    sparse = MHTTracker(MHTConfig(), KnownClutter(1e-9))
    sparse.step(scan)
    assert len(sparse.leaves) == 3


def _tied_scores(rng, n):
    """Scores with exact ties and near-ties (1e−13 apart) and a wide range."""
    base = np.round(rng.normal(0, 3, n) * 2) / 2
    return base + rng.choice([0.0, 1e-13, -1e-13, 1e6], n, p=[0.7, 0.1, 0.1, 0.1])


def test_cap_leaves_per_tree_equals_ranking_every_tree():
    """Ranking only the trees over the cap gives the keep mask of the former formula,
    every leaf ranked (``_rank_in_groups`` over all rows), ties and near-ties included;
    and what a brute force (sort by score descending, then index) keeps."""
    from mhtrack.mht.pruning import _rank_in_groups
    from mhtrack.mht.tree import segment_ids

    rng = np.random.default_rng(7)
    for _ in range(300):
        n_trees = int(rng.integers(1, 12))
        tree = np.sort(rng.integers(0, n_trees, int(rng.integers(0, 80))))
        score = _tied_scores(rng, tree.size)
        cap = int(rng.integers(1, 10))
        keep, cut = cap_leaves_per_tree(tree, score, cap)
        if tree.size:
            former = _rank_in_groups(segment_ids(tree)[1], score) < cap
            if np.diff(np.r_[0, np.flatnonzero(np.diff(tree)) + 1, tree.size]).max() <= cap:
                former[:] = True
            np.testing.assert_array_equal(keep, former)
        assert cut == tree.size - keep.sum()
        half = np.round(score * 2) / 2  # exact ties only: the brute force's order
        keep, _ = cap_leaves_per_tree(tree, half, cap)
        brute = np.zeros(tree.size, bool)
        for t in np.unique(tree):
            idx = np.flatnonzero(tree == t)
            brute[sorted(idx, key=lambda i: (-half[i], i))[:cap]] = True
        np.testing.assert_array_equal(keep, brute)


def test_cap_leaves_per_tree_ties_as_over_all_leaves():
    """Scores 1e−8 apart in a tree over the cap are a tie when another tree's score
    spans 1e9 (the key's resolution is relative to the range of all leaves): the lower
    index is kept, as when every leaf was ranked."""
    tree = np.array([0, 1, 1, 1])
    score = np.array([1e9, 0.0, 1e-8, -5.0])
    keep, cut = cap_leaves_per_tree(tree, score, 1)
    assert keep.tolist() == [True, True, False, False] and cut == 2


def test_score_drop_keep_equals_the_per_tree_maximum():
    rng = np.random.default_rng(3)
    for _ in range(200):
        tree = np.sort(rng.integers(0, 9, int(rng.integers(0, 60))))
        score = _tied_scores(rng, tree.size)
        ref = np.array([score[i] >= score[tree == tree[i]].max() - 12.0
                        for i in range(tree.size)], bool)
        np.testing.assert_array_equal(score_drop_keep(tree, score, 12.0), ref)


def test_prune_after_solve_equals_the_former_tree_cap():
    """N-scan pruning then the cap on trees, as the former code wrote it: the cap called
    on the kept leaves whenever they outnumber ``max_trees`` (here with trees over and
    under the limit, and limits the kept leaves do and do not exceed)."""
    from dataclasses import replace

    from frame_fixture import frame
    from leaves_fixture import leaves_of_trees

    from mhtrack.mht.pruning import cap_trees, n_scan_keep, prune_after_solve

    rng = np.random.default_rng(11)
    for _ in range(60):
        lv = leaves_of_trees(rng, int(rng.integers(1, 80)), np.arange(30))
        chosen = np.unique(rng.choice(len(lv), int(rng.integers(0, 6))))
        max_trees = int(rng.integers(1, 40))
        keep = n_scan_keep(lv.tree, lv.window[:, 0], chosen)
        is_chosen = np.zeros(len(lv), bool)
        is_chosen[chosen] = True
        ref_caps: dict[str, int] = {}
        if keep.sum() > max_trees:
            prot = is_chosen | (lv.track >= 0)
            kt, cut = cap_trees(lv.tree[keep], lv.score[keep], prot[keep], max_trees)
            if cut:
                ref_caps["max_trees"] = cut
                keep[np.flatnonzero(keep)[~kt]] = False
        f = frame(max_trees=max_trees)
        got = prune_after_solve(f, lv, chosen)
        ref = replace(lv.take(np.flatnonzero(keep)), chosen=is_chosen[keep])
        assert f.caps == ref_caps
        for name, a in ref.arrays().items():
            np.testing.assert_array_equal(got.arrays()[name], a, err_msg=name)
