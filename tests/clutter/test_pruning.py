"""The two component-deletion rules: P1 eq. 12 (AGMM) and a fixed threshold (GMM)."""

import numpy as np
import pytest

from mhtrack.clutter import keep_above, keep_mass


def test_eq12_hand_example() -> None:
    # 0.5 + 0.3 = 0.8 <= 0.92, 0.5 + 0.3 + 0.15 = 0.95 > 0.92: keep three
    np.testing.assert_array_equal(keep_mass(np.array([0.5, 0.3, 0.15, 0.05])),
                                  [True, True, True, False])


def test_eq12_ranks_by_weight_not_position() -> None:
    np.testing.assert_array_equal(keep_mass(np.array([0.05, 0.15, 0.5, 0.3])),
                                  [False, True, True, True])


def test_eq12_strict_inequality_and_equal_weights() -> None:
    # a prefix summing to exactly 0.92 is not "above 0.92"
    np.testing.assert_array_equal(keep_mass(np.array([0.92, 0.08])), [True, True])
    np.testing.assert_array_equal(keep_mass(np.array([0.93, 0.07])), [True, False])
    assert keep_mass(np.full(4, 0.25)).all()  # 0.75 <= 0.92 < 1
    assert keep_mass(np.full(13, 1 / 13)).sum() == 12  # 12/13 = 0.923 > 0.92
    assert keep_mass(np.array([1.0])).all()
    assert keep_mass(np.zeros(0)).size == 0


@pytest.mark.parametrize("mass", [0.5, 0.8, 0.92, 0.99])
def test_eq12_keeps_the_fewest(mass: float) -> None:
    w = np.random.default_rng(int(mass * 100)).dirichlet(np.ones(10))
    keep = keep_mass(w, mass)
    assert w[keep].sum() > mass
    # dropping the smallest kept one would fall to or below the mass
    assert w[keep].sum() - w[keep].min() <= mass
    assert w[keep].min() >= w[~keep].max(initial=0.0)


def test_fixed_threshold() -> None:
    np.testing.assert_array_equal(keep_above(np.array([0.5, 0.3, 0.15, 0.05]), 0.1),
                                  [True, True, True, False])
    np.testing.assert_array_equal(keep_above(np.array([0.5, 0.3, 0.15, 0.05]), 0.05),
                                  [True, True, True, True])
    np.testing.assert_array_equal(keep_above(np.full(4, 0.25), 0.3), [True, False, False, False])
