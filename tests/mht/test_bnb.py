"""The unrolled two-tree search makes exactly the generic search's choice, ties and
rounding included, and hands the node limit over to it."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.mht.bnb import search, search_two

#: Scores whose sums round differently by order (0.1 + 0.2 != 0.3) and repeat (ties).
TIED = [0.1, 0.2, 0.3, 0.3, 0.6, 0.7, 1.0, 1.0, 2.0]


def _options(seed: int, p: int, q: int, n_plots: int, tied: bool) -> list[list[tuple]]:
    """Two trees of ``p`` and ``q`` leaves, each leaf on a random set of plots (a bit
    mask, possibly empty), scores from :data:`TIED` or continuous; each tree best first,
    ties by lower leaf (as :func:`~mhtrack.mht.bnb.solve_small` builds them)."""
    rng = np.random.default_rng(seed)
    leaves = rng.permutation(p + q).tolist()
    out = []
    for tree_leaves in (leaves[:p], leaves[p:]):
        opts = []
        for i in tree_leaves:
            sc = float(rng.choice(TIED)) if tied else float(rng.uniform(0.01, 3.0))
            mask = int(sum(1 << int(b) for b in rng.choice(n_plots, rng.integers(0, 3))))
            opts.append((sc, mask, i))
        opts.sort(key=lambda o: (-o[0], o[2]))
        out.append(opts)
    return out


@settings(max_examples=2000, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), p=st.integers(1, 7), q=st.integers(1, 7),
       n_plots=st.integers(1, 6), tied=st.booleans())
def test_search_two_equals_search(seed, p, q, n_plots, tied):
    options = _options(seed, p, q, n_plots, tied)
    want = search([list(o) for o in options], 5_000)
    assert search_two([list(o) for o in options], 5_000) == want


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), p=st.integers(1, 6), q=st.integers(1, 6),
       limit=st.integers(1, 40))
def test_search_two_passes_the_node_limit_as_search(seed, p, q, limit):
    options = _options(seed, p, q, 3, True)
    want = search([list(o) for o in options], limit)
    assert search_two([list(o) for o in options], limit) == want


def test_search_two_order_of_trees_does_not_matter():
    """Trees given worst first: the search still takes the best tree first."""
    a = [(1.0, 0b01, 0)]
    b = [(2.0, 0b01, 1), (0.5, 0b10, 2)]
    assert search_two([list(a), list(b)], 100) == search([list(a), list(b)], 100) == [1]
    assert search_two([list(b), list(a)], 100) == [1]


def test_search_two_hand_worked():
    """A: leaves 0 (3.0, plot 1) and 1 (1.0, plot 2); B: leaf 2 (2.5, plot 1). Greedy
    takes 0 alone (3.0); 1 + 2 gives 3.5, the optimum."""
    a = [(3.0, 0b01, 0), (1.0, 0b10, 1)]
    b = [(2.5, 0b01, 2)]
    assert search_two([a, b], 100) == [1, 2]
