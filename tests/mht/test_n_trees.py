"""``Leaves.n_trees``."""

import numpy as np


def test_n_trees_counts_the_runs_of_tree_ids():
    """Leaves.n_trees: the number of distinct tree ids (leaves sorted by tree)."""
    import dataclasses

    from mhtrack.mht.tree import Leaves
    assert Leaves.empty(3, 1).n_trees == 0
    for tree in ([4], [0, 0, 0], [0, 1, 1, 5, 5, 5, 9]):
        lv = dataclasses.replace(Leaves.empty(3, 1), tree=np.asarray(tree, np.int64))
        assert lv.n_trees == len(set(tree))
