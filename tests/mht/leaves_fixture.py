"""Random leaf stores for the tests of the store's operations (take, concat, numbering)."""

import numpy as np

from mhtrack.mht.tree import Leaves


def random_leaves(rng, n, tree=None, r=2, width=4):
    """``n`` leaves with random columns, IMM of ``r`` models and windows of ``width``
    scans; ``tree`` (sorted) or random tree ids 0–8."""
    if tree is None:
        tree = np.sort(rng.integers(0, 9, n))
    f = rng.normal(size=n)
    i = rng.integers(-1, 50, n)
    return Leaves(rng.normal(size=(n, 4)), rng.normal(size=(n, 4, 4)), f, f + 1, tree, i,
                  i + 1, i + 2, rng.integers(-1, 99, (n, width)), rng.random(n) < 0.5,
                  rng.random((n, r)), rng.normal(size=(n, r, 4)),
                  rng.normal(size=(n, r, 4, 4)), i + 3, i + 4, f + 2,
                  rng.normal(size=(n, 7)), rng.integers(-1, 1 << 24, (n, 2)))


def leaves_of_trees(rng, n, trees):
    """:func:`random_leaves` whose tree ids are drawn from ``trees`` (then sorted)."""
    return random_leaves(rng, n, np.sort(rng.choice(trees, n)))
