"""The estimated shrinkage of the map-calibrated GMM (``mhtrack.clutter.shrinkage``)
against a hand-worked example and the property that Poisson-consistent counts leave the
GMM unchanged; one discount rule for every forgetting estimator; ``forget`` takes used
plots out of ``S`` only."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.clutter.calibrated import MapCalibratedClutter
from mhtrack.clutter.discount import discount
from mhtrack.clutter.forgetting import ForgettingGMMClutter
from mhtrack.clutter.gmm import GMMClutter
from mhtrack.clutter.known import KnownClutter
from mhtrack.clutter.radar_map import ClutterMap
from mhtrack.clutter.shrinkage import Z_OVERDISPERSED, prior_count, shrunk_ratio
from mhtrack.records import Scan


def test_prior_count_by_hand() -> None:
    """S = (0, 10, 2, 8), E = (4, 4, 4, 4), φ = 1: Σ[(S−E)² − S] = (16−0)+(36−10)+(4−2)
    +(16−8) = 52, ΣE² = 64, T = 52/√128 = 4.60 > 1.645, v̂ = 52/64, b = 64/52;
    r̂ = (S + b)/(E + b): (0 + 1.2308)/(5.2308) = 0.2353 for the first cell. With φ = 2:
    Σ[(S−E)² − 2S] = 32, T = 32/(2√128) = 1.41 < 1.645: no shrinkage estimate, b = ∞."""
    s, e = np.array([0.0, 10, 2, 8]), np.full(4, 4.0)
    b = prior_count(s, e)
    assert b == pytest.approx(64 / 52)
    np.testing.assert_allclose(shrunk_ratio(s, e, b), (s + 64 / 52) / (e + 64 / 52))
    assert shrunk_ratio(s, e, b)[0] == pytest.approx(0.23529, rel=1e-4)
    assert prior_count(s, e, phi=2.0) == np.inf
    np.testing.assert_array_equal(shrunk_ratio(s, e, np.inf), np.ones(4))
    assert pytest.approx(1.6448536, rel=1e-7) == Z_OVERDISPERSED


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.0, 50.0), min_size=1, max_size=200),
       st.floats(0.05, 1.0))
def test_counts_equal_to_expected_leave_every_ratio_one(e: list[float], phi: float) -> None:
    """Counts exactly the expected (no over-dispersion at all): ``b = ∞``, every ratio 1."""
    e_a = np.asarray(e)
    assert prior_count(e_a, e_a, phi) == np.inf
    np.testing.assert_array_equal(shrunk_ratio(e_a, e_a, prior_count(e_a, e_a, phi)), 1.0)


def test_poisson_counts_shrink_fully_in_most_draws_and_overdispersed_ones_do_not() -> None:
    """Poisson(E) counts on 500 cells: the test rejects in about its 5 % of 400 draws
    (≤ 10 %), and then ``b̂`` is large (``v̂ = 1/b̂ < 0.02``, the ratios' prior σ < 15 %);
    counts of Poisson(r E) with
    r ~ Gamma(4, 4) (v = 0.25): ``b̂`` within 35 % of 4 in each of 20 draws."""
    rng = np.random.default_rng(7)
    e = rng.uniform(0.5, 20.0, 500)
    bs = np.array([prior_count(rng.poisson(e).astype(float), e) for _ in range(400)])
    assert np.mean(np.isfinite(bs)) <= 0.10
    assert (bs[np.isfinite(bs)] > 50.0).all()
    for _ in range(20):
        s = rng.poisson(e * rng.gamma(4.0, 0.25, e.size)).astype(float)
        assert prior_count(s, e) == pytest.approx(4.0, rel=0.35)


def _disc(rng: np.random.Generator, n: int, r: float = 10_000.0) -> np.ndarray:
    rr, t = r * np.sqrt(rng.random(n)), 2 * np.pi * rng.random(n)
    return np.column_stack([rr * np.sin(t), rr * np.cos(t)])


def test_mapgmm_equals_its_base_on_uniform_clutter() -> None:
    """Uniform clutter, the true model for a constant base: after 40 rotations the
    estimated shrinkage leaves the base unchanged (every ratio 1), where the former fixed
    ``b₀ = 5`` moved every cell by its Poisson noise."""
    rng = np.random.default_rng(5)
    kappa = 150 / (np.pi * 1e8)
    est = MapCalibratedClutter(base=KnownClutter(kappa), range_cell=2500.0, n_azimuth=8,
                               max_range=10_000.0)
    fixed = MapCalibratedClutter(base=KnownClutter(kappa), range_cell=2500.0, n_azimuth=8,
                                 max_range=10_000.0, prior_count=5.0)
    for k in range(40):
        z = _disc(rng, rng.poisson(150))
        for e in (est, fixed):
            e.update(Scan(k, 4.0 * k, z, np.zeros(len(z), np.int64), np.arange(len(z))))
    q = _disc(rng, 50)
    np.testing.assert_array_equal(est.intensity(q), np.full(50, kappa))
    assert np.abs(fixed.ratio() - 1).max() > 0.02


def test_one_discount_rule_and_both_is_an_error() -> None:
    """``γ = 2^(−Δt/h)`` with a half-life, else the constant; the map and the forgetting
    mixture take it from the same function, and reject both given."""
    assert discount(None, 5.0, forgetting=None, half_life=10.0) == 1.0
    assert discount(3.0, 8.0, forgetting=None, half_life=10.0) == pytest.approx(2 ** -0.5)
    assert discount(3.0, 8.0, forgetting=0.7, half_life=None) == 0.7
    for cls in (ClutterMap, ForgettingGMMClutter, MapCalibratedClutter):
        with pytest.raises(ValueError, match="not both"):
            cls(forgetting=0.9, half_life=10.0)
    m, f = ClutterMap(half_life=10.0), ForgettingGMMClutter(half_life=10.0)
    assert m._discount(0.0) == f._discount(0.0) == 1.0
    assert m._discount(5.0) == f._discount(5.0) == pytest.approx(2 ** -0.5)
    m, f = ClutterMap(forgetting=0.8), ForgettingGMMClutter(forgetting=0.8)
    assert m._discount(0.0) == f._discount(0.0) == 0.8


def test_forget_takes_used_plots_out_of_the_counts_not_the_expected() -> None:
    rng = np.random.default_rng(1)
    est = MapCalibratedClutter(base=GMMClutter(), range_cell=2500.0, n_azimuth=8,
                               max_range=10_000.0)
    z = _disc(rng, 120)
    est.update(Scan(0, 0.0, z, np.zeros(120, np.int64), np.arange(120)))
    s0, e0 = est.counts.sums_.sum(), est.expected_.copy()
    est.forget(np.arange(120) < 10)
    assert est.counts.sums_.sum() == s0 - 10
    np.testing.assert_array_equal(est.expected_, e0)


def _smooth_with_roll(a: np.ndarray, passes: int) -> np.ndarray:
    """The former ``smooth_cells`` (np.roll and np.vstack), the reference."""
    out = np.asarray(a, float)
    for _ in range(passes):
        out = 0.5 * out + 0.25 * (np.roll(out, 1, axis=1) + np.roll(out, -1, axis=1))
        if out.shape[0] > 1:
            up, down = np.vstack([out[:1], out[:-1]]), np.vstack([out[1:], out[-1:]])
            out = 0.5 * out + 0.25 * (up + down)
    return out


@pytest.mark.parametrize("shape", [(1, 1), (1, 5), (3, 1), (7, 9), (24, 64)])
def test_smooth_cells_gives_the_former_floats_also_stacked(shape: tuple[int, int]) -> None:
    from mhtrack.clutter.radar_map import smooth_cells

    rng = np.random.default_rng(sum(shape))
    a = rng.random(shape) * 10.0 ** rng.integers(-5, 5, shape)
    for p in (0, 1, 2, 3):
        ref = _smooth_with_roll(a, p)
        assert smooth_cells(a, p).tobytes() == ref.tobytes()
        both = smooth_cells(np.stack([a, 2 * a]), p)
        assert both[0].tobytes() == ref.tobytes()
        assert both[1].tobytes() == _smooth_with_roll(2 * a, p).tobytes()
