"""The store after a scan with its states copied once (``deferred_concat`` then
``take_deferred``, as the tracker runs it) holds bit for bit the arrays of the former
path: concatenate every column, then take the rows N-scan pruning keeps."""

from dataclasses import replace

import numpy as np
import pytest
from frame_fixture import frame
from leaves_fixture import leaves_of_trees

from mhtrack.mht.numbering import Counter, number_and_merge
from mhtrack.mht.pruning import prune_after_solve
from mhtrack.mht.tree import STATE, Leaves, deferred_concat, take_deferred


def _same(got: Leaves, ref: Leaves) -> None:
    for name, a in ref.arrays().items():
        b = got.arrays()[name]
        assert b.dtype == a.dtype and b.shape == a.shape, name
        np.testing.assert_array_equal(b, a, err_msg=name)


@pytest.mark.parametrize("seed", range(12))
def test_take_deferred_equals_concat_then_take(seed):
    rng = np.random.default_rng(seed)
    a = leaves_of_trees(rng, int(rng.integers(0, 40)), np.arange(20))
    b = leaves_of_trees(rng, int(rng.integers(1, 10)), np.arange(20, 30))
    lazy = deferred_concat(a, b)
    assert all(np.isnan(getattr(lazy, f)).all() for f in STATE)  # placeholders, not states
    full = Leaves.concat(a, b)
    chosen = rng.random(len(full)) < 0.3
    rows = np.flatnonzero(rng.random(len(full)) < 0.6)
    _same(take_deferred(lazy, rows, (a, b), chosen=chosen[rows]),
          replace(full.take(rows), chosen=chosen[rows]))
    _same(take_deferred(lazy, None, (a, b), chosen=chosen), replace(full, chosen=chosen))


@pytest.mark.parametrize("seed", range(8))
def test_prune_after_solve_with_parts_is_the_same(seed):
    """The tracker's path (numbering with ``defer_states``, pruning with ``parts``) against
    numbering and pruning the concatenated store."""
    rng = np.random.default_rng(100 + seed)
    grown = leaves_of_trees(rng, int(rng.integers(5, 60)), np.arange(25))
    births = leaves_of_trees(rng, int(rng.integers(1, 8)), np.arange(25, 33))
    idle = Leaves.empty(grown.window.shape[1], grown.n_models)
    ref = number_and_merge(grown, births, idle, Counter(9))
    lazy = number_and_merge(grown, births, idle, Counter(9), defer_states=True)
    chosen = np.unique(rng.choice(len(ref), 6))
    for max_trees in (1000, 12):
        f_ref, f_got = frame(max_trees=max_trees), frame(max_trees=max_trees)
        _same(prune_after_solve(f_got, lazy, chosen, parts=(grown, births)),
              prune_after_solve(f_ref, ref, chosen))
        assert f_got.caps == f_ref.caps


def test_placeholders_are_read_only_nans_and_columns_replace():
    """``deferred_concat``'s placeholders: the shape of the concatenated column, every
    element NaN, no memory (all strides 0), not writable; ``columns`` take the place of
    the concatenated ones."""
    rng = np.random.default_rng(0)
    a = leaves_of_trees(rng, 7, np.arange(5))
    b = leaves_of_trees(rng, 3, np.arange(5, 8))
    node = np.arange(100, 100 + len(a) + len(b))
    lazy = deferred_concat(a, b, node=node)
    full = Leaves.concat(a, b)
    for f in STATE:
        p = getattr(lazy, f)
        assert p.shape == getattr(full, f).shape and p.dtype == np.float64, f
        assert not any(p.strides) and not p.flags.writeable, f
        with pytest.raises(ValueError):
            p[...] = 0.0
    assert lazy.node is node
    for name, v in full.arrays().items():
        if name not in STATE and name != "node":
            np.testing.assert_array_equal(lazy.arrays()[name], v, err_msg=name)
