"""Plot conflicts when trees step on their own looks (``by_id``): hand-worked windows."""

from __future__ import annotations

import numpy as np

from mhtrack.mht import best_hypothesis, plot_keys
from mhtrack.mht.pruning import n_scan_keep

# tree 0 used plot 7 two looks ago (column 1); tree 1 looked once more, so it holds
# plot 7 in column 0. By column they do not conflict; by id they do.
WINDOW = np.array([[-1, 7, -1, 9], [7, -1, -1, 8]])
TREE = np.array([0, 1])


def test_plot_keys_by_id_names_a_plot_whatever_its_column() -> None:
    _, by_col = plot_keys(WINDOW)
    _, by_id = plot_keys(WINDOW, by_id=True)
    assert len(set(by_col.tolist())) == 4  # (1, 7), (3, 9), (0, 7), (3, 8)
    assert len(set(by_id.tolist())) == 3  # 7, 8, 9


def test_best_hypothesis_by_id_keeps_one_of_two_trees_sharing_a_plot() -> None:
    score = np.array([5.0, 3.0])
    assert best_hypothesis(score, TREE, WINDOW).leaves.tolist() == [0, 1]
    assert best_hypothesis(score, TREE, WINDOW, by_id=True).leaves.tolist() == [0]


def test_n_scan_keep_by_window_prunes_either_way() -> None:
    # chosen leaf 0 (tree 0) decides plot 7 at its oldest column; leaf 1 (tree 1) holds
    # plot 7 in column 2: kept by the scan rule, pruned when looks differ.
    window = np.array([[7, 5, -1, 9], [-1, -1, 7, 8]])
    tree, chosen = np.array([0, 1]), np.array([0])
    assert n_scan_keep(tree, window[:, 0], chosen).tolist() == [True, True]
    assert n_scan_keep(tree, window[:, 0], chosen, window).tolist() == [True, False]
    # the other way: leaf 1's own oldest plot 5 sits in column 1 of the chosen leaf
    window = np.array([[7, 5, -1, 9], [5, -1, -1, 8]])
    assert n_scan_keep(tree, window[:, 0], chosen).tolist() == [True, True]
    assert n_scan_keep(tree, window[:, 0], chosen, window).tolist() == [True, False]
