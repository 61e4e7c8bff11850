"""``number_and_merge``: the store after a scan in one copy equals the composition it
replaced — node ids for the grown then new leaves, then the idle trees merged in tree
order (stable)."""

from dataclasses import replace

import numpy as np
import pytest
from leaves_fixture import leaves_of_trees, random_leaves

from mhtrack.mht.numbering import Counter, number_and_merge, number_nodes
from mhtrack.mht.tree import Leaves


def _reference(grown, births, idle, nodes):
    """The former path: concat, number, concat with the idle leaves, stable sort by tree."""
    both = Leaves.concat(grown, births)
    first = nodes.take(len(both))
    stepped = replace(both, node=np.arange(first, first + len(both), dtype=np.int64))
    if len(idle) == 0:
        return stepped
    out = Leaves.concat(stepped, idle)
    order = np.argsort(out.tree, kind="stable")
    return out.take(order)


@pytest.mark.parametrize("seed", range(20))
def test_number_and_merge_equals_the_composition(seed):
    rng = np.random.default_rng(seed)
    ids = rng.permutation(30)  # new trees take ids above every existing tree's
    stepped_trees, idle_trees, new_trees = ids[:15], ids[15:], np.arange(30, 40)
    grown = leaves_of_trees(rng, int(rng.integers(0, 30)), stepped_trees)
    births = leaves_of_trees(rng, int(rng.integers(0, 6)), new_trees)
    idle = leaves_of_trees(rng, int(rng.integers(0, 30)) * int(seed % 4 != 0), idle_trees)
    start = int(rng.integers(0, 1000))
    got = number_and_merge(grown, births, idle, Counter(start))
    ref = _reference(grown, births, idle, Counter(start))
    for name, a in ref.arrays().items():
        np.testing.assert_array_equal(got.arrays()[name], a, err_msg=name)
    assert np.all(np.diff(got.tree) >= 0)


@pytest.mark.parametrize("seed", range(5))
def test_grown_leaves_out_of_tree_order_are_sorted_alike(seed):
    """The one-write merge takes sorted parts; other orders go through the stable sort."""
    rng = np.random.default_rng(seed)
    grown = leaves_of_trees(rng, 12, np.arange(10))
    grown = grown.take(rng.permutation(12))
    births = leaves_of_trees(rng, 3, np.arange(20, 23))
    idle = leaves_of_trees(rng, 9, np.arange(10, 20))
    got = number_and_merge(grown, births, idle, Counter(5))
    ref = _reference(grown, births, idle, Counter(5))
    for name, a in ref.arrays().items():
        np.testing.assert_array_equal(got.arrays()[name], a, err_msg=name)


def test_hand_worked_node_ids():
    """Two grown leaves and one new leaf get ids 7, 8, 9 in row order; the idle leaf of
    tree 1 keeps its id and lands between trees 0 and 2."""
    rng = np.random.default_rng(0)
    grown = replace(random_leaves(rng, 2), tree=np.array([0, 2]))
    births = replace(random_leaves(rng, 1), tree=np.array([5]))
    idle = replace(random_leaves(rng, 1), tree=np.array([1]), node=np.array([42]))
    out = number_and_merge(grown, births, idle, Counter(7))
    np.testing.assert_array_equal(out.tree, [0, 1, 2, 5])
    np.testing.assert_array_equal(out.node, [7, 42, 8, 9])
    assert number_nodes(Leaves.concat(grown, births), Counter(7)).node.tolist() == [7, 8, 9]
