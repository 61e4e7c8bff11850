"""``tree.filled`` is ``np.full``: same values, dtype and shape (empty included)."""

import numpy as np
import pytest

from mhtrack.mht.tree import filled


@pytest.mark.parametrize(("n", "value", "dtype"), [(0, -1, np.int64), (5, -1, np.int64),
                                                   (7, 3.5, float), (3, 12, np.int64),
                                                   (4, np.nan, float)])
def test_filled_is_np_full(n, value, dtype):
    got, want = filled(n, value, dtype), np.full(n, value, dtype)
    assert got.dtype == want.dtype and got.shape == want.shape
    assert got.tobytes() == want.tobytes()


def test_n_trees_counts_the_runs_of_tree_ids():
    """Leaves.n_trees: the number of distinct tree ids (leaves sorted by tree)."""
    import dataclasses

    from mhtrack.mht.tree import Leaves
    assert Leaves.empty(3, 1).n_trees == 0
    for tree in ([4], [0, 0, 0], [0, 1, 1, 5, 5, 5, 9]):
        lv = dataclasses.replace(Leaves.empty(3, 1), tree=np.asarray(tree, np.int64))
        assert lv.n_trees == len(set(tree))
