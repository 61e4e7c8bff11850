"""The cheaper paths of the front of the MHT cycle give what the plain forms give: rows
taken with ``ndarray.take`` as with fancy indexing, the looked-at trees as a per-tree
maximum, the miss increments as the scalar increment per leaf, scan checks as before."""

import math

import numpy as np
import pytest
from leaves_fixture import random_leaves

from mhtrack.mht.scoring import miss_increment, miss_increments
from mhtrack.mht.timed import looked_trees
from mhtrack.mht.tree import segment_starts
from mhtrack.mht.validate import validate_scan
from mhtrack.records import Scan


@pytest.mark.parametrize("seed", range(5))
def test_take_equals_fancy_indexing(seed):
    rng = np.random.default_rng(seed)
    lv = random_leaves(rng, 30)
    for idx in (rng.integers(0, 30, 50), rng.random(30) < 0.4, np.zeros(0, np.int64), [],
                [3, -1, 0], slice(2, 9)):
        got = lv.take(idx)
        key = idx if isinstance(idx, slice) else np.asarray(idx, dtype=None if len(idx)
                                                            else np.int64)
        for name, a in lv.arrays().items():
            want = a[key]
            b = getattr(got, name)
            assert b.dtype == want.dtype and b.shape == want.shape
            assert np.array_equal(b, want), name


def test_looked_trees_is_the_per_tree_maximum():
    rng = np.random.default_rng(3)
    for _ in range(500):
        n = int(rng.integers(0, 40))
        tree = np.sort(rng.integers(0, 12, n))
        pd = np.where(rng.random(n) < rng.random(), 0.0, 0.8)
        want = np.array([(pd[tree == t] > 0).any() for t in tree], bool)
        got = looked_trees(tree, pd)
        assert got.dtype == bool and np.array_equal(got, want)
        if n:
            assert np.array_equal(segment_starts(tree),
                                  [k for k in range(n) if k == 0 or tree[k] != tree[k - 1]])


def test_miss_increments_are_the_scalar_increment_of_each_leaf():
    rng = np.random.default_rng(4)
    for pd in (np.full(7, 0.9), rng.choice([0.0, 0.85, 0.9], 40), rng.choice([0.0, 0.8], 9),
               np.zeros(0), np.zeros(3)):
        for pg in (None, 0.999):
            got = miss_increments(pd, pg)
            want = [miss_increment(float(p), pg) for p in pd]
            assert got.dtype == float and got.shape == pd.shape
            assert got.tobytes() == np.array(want, float).reshape(pd.shape).tobytes()
    assert miss_increments(np.array([0.5]))[0] == math.log1p(-0.5)


@pytest.mark.parametrize(("z", "message"), [
    ([[0.0, 1.0], [np.nan, 2.0], [2e9, 0.0]], "row 11 has a non-finite position"),
    ([[0.0, 1.0], [1.0, 2.0], [2e9, 0.0]], "row 12 lies at"),
    ([[0.0, 1.0], [1.0, np.inf], [2.0, 0.0]], "row 11 has a non-finite position"),
])
def test_scan_check_reports_the_first_bad_plot(z, message):
    scan = Scan(0, 1.0, np.array(z), np.zeros(3, np.int64), np.array([10, 11, 12]))
    with pytest.raises(ValueError, match=message):
        validate_scan(scan, np.eye(2), None, None)


def test_scan_check_of_rows_and_covariances():
    z = np.zeros((3, 2))
    rows = np.array([5, 3, 5])
    with pytest.raises(ValueError, match="not unique"):
        validate_scan(Scan(0, 1.0, z, np.zeros(3, np.int64), rows), np.eye(2), None, None)
    ok = np.array([7, 3, 5])  # unique, not ascending
    R = np.stack([np.eye(2), np.full((2, 2), np.nan), np.eye(2) * 4])
    _, R2, _ = validate_scan(Scan(0, 1.0, z, np.zeros(3, np.int64), ok, R), np.eye(2) * 9,
                             None, None)
    assert np.array_equal(R2[1], np.eye(2) * 9) and np.array_equal(R2[2], np.eye(2) * 4)
    R[2, 0, 0] = -1.0
    with pytest.raises(ValueError, match="row 5 has an invalid covariance"):
        validate_scan(Scan(0, 1.0, z, np.zeros(3, np.int64), ok, R), np.eye(2), None, None)
