"""The forgetting mixture against the batch EM (the GMM's code path, scikit-learn), its
moments against direct sums, and its behaviour on drifting and splitting clumps."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.clutter.em import fit_em
from mhtrack.clutter.forgetting import ForgettingGMMClutter
from mhtrack.clutter.moments import gaussian_moments, plot_moments, principal_kurtosis, shift
from mhtrack.records import Scan


def _scan(k: int, z: np.ndarray) -> Scan:
    z = np.asarray(z, float).reshape(-1, 2)
    return Scan(k, float(k), z, np.zeros(len(z), np.int64), np.arange(len(z)))


def _clumps(rng: np.random.Generator, centres: list[tuple[float, float]], n: int,
            sigma: float) -> np.ndarray:
    return np.vstack([rng.normal(c, sigma, (n, 2)) for c in centres])


_PLAIN = dict(background=False, min_points=0.0, min_contrast=0.0, merge_distance=0.0,
              split_kurtosis=0.0, tol=0.0)


def test_factor_one_on_one_scan_is_the_batch_em_of_the_gmm() -> None:
    """γ = 1, every plot in one scan, no pruning, merging or splitting: the same mixture
    as :func:`fit_em` (the GMM's EM) run from the same start for the same iterations."""
    rng = np.random.default_rng(5)
    z = _clumps(rng, [(0, 0), (3000, 500), (-2000, 2500)], 60, 300.0)
    est = ForgettingGMMClutter(forgetting=1.0, n_components=3, max_iter=15, **_PLAIN)
    est.update(_scan(0, z))
    ref = fit_em(z, est.start_, reg_covar=est.reg_covar, tol=0.0, max_iter=15).mixture
    got = est.mixture_
    order = np.lexsort(got.means.T[::-1])
    ref_order = np.lexsort(ref.means.T[::-1])
    np.testing.assert_allclose(got.means[order], ref.means[ref_order], rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(got.covariances[order], ref.covariances[ref_order], rtol=1e-8)
    np.testing.assert_allclose(got.weights[order], ref.weights[ref_order], rtol=1e-9)


def test_factor_one_over_many_scans_approaches_scikit_learn_on_the_pooled_plots() -> None:
    """γ = 1 on stationary clumps fed a scan at a time: online EM's fit is close to
    scikit-learn's batch ``GaussianMixture`` on all plots pooled (means within a tenth of
    σ, weights within 0.02)."""
    mixture = pytest.importorskip("sklearn.mixture")
    rng = np.random.default_rng(8)
    centres = [(0.0, 0.0), (4000.0, 1000.0), (-3000.0, 3000.0)]
    est = ForgettingGMMClutter(forgetting=1.0, n_components=3, max_iter=30, tol=1e-6,
                               background=False)
    scans = [_clumps(rng, centres, 15, 250.0) for _ in range(20)]
    for k, z in enumerate(scans):
        est.update(_scan(k, z))
    pooled = np.vstack(scans)
    sk = mixture.GaussianMixture(3, covariance_type="full", random_state=0, n_init=3,
                                 reg_covar=100.0).fit(pooled)
    got = est.mixture_
    assert got.n_components == 3
    for mu, w in zip(sk.means_, sk.weights_, strict=True):
        j = int(np.argmin(np.linalg.norm(got.means - mu, axis=1)))
        assert np.linalg.norm(got.means[j] - mu) < 25.0
        assert abs(got.weights[j] - w) < 0.02
    assert est.count_ == pytest.approx(45.0)


def test_forgetting_follows_a_drifting_clump_closer_than_no_forgetting() -> None:
    """A clump moving ``v`` = 100 m per scan: the forgetting mean lags by about
    ``v γ/(1 − γ)`` = 150 m for γ = 0.6 (the exponential average of a ramp), the plain
    mean (γ = 1) by half the path, ~1450 m."""
    rng = np.random.default_rng(2)
    ests = {g: ForgettingGMMClutter(forgetting=g, n_components=2) for g in (0.6, 1.0)}
    for k in range(30):
        centre = (100.0 * k, 0.0)
        z = np.vstack([_clumps(rng, [centre], 20, 150.0),
                       rng.uniform(-5000, 5000, (10, 2))])
        for e in ests.values():
            e.update(_scan(k, z))
    err = {g: np.min(np.linalg.norm(e.mixture_.means - [2900.0, 0.0], axis=1))
           for g, e in ests.items()}
    assert err[0.6] < 300.0 and err[1.0] > 1000.0


def test_a_clump_that_splits_in_two_is_followed_by_two_gaussians() -> None:
    """One clump parting into two along x: with the kurtosis split the mixture ends with
    a Gaussian near each part; without it (and starting from one) one broad Gaussian."""
    rng = np.random.default_rng(4)

    def run(split: float) -> np.ndarray:
        e = ForgettingGMMClutter(forgetting=0.7, n_components=4, split_kurtosis=split,
                                 min_contrast=0.0)
        for k in range(25):
            h = 60.0 * k
            z = _clumps(rng, [(-h, 0.0), (h, 0.0)], 25, 120.0)
            e.update(_scan(k, z))
        return e.mixture_.means

    final = np.array([[-1440.0, 0.0], [1440.0, 0.0]])
    means = run(2.0)
    assert all(np.min(np.linalg.norm(means - c, axis=1)) < 200.0 for c in final)


@given(st.integers(0, 2**32 - 1))
@settings(max_examples=25, deadline=None)
def test_moment_shift_equals_direct_sums(seed: int) -> None:
    """Moving the anchor by the binomial expansion = summing about the new anchor."""
    rng = np.random.default_rng(seed)
    z = rng.normal(0, 500, (40, 2)) + rng.uniform(-1e4, 1e4, 2)
    a = rng.normal(0, 2000, (3, 2))
    b = rng.normal(0, 2000, (3, 2))
    r = rng.random((3, 40))
    np.testing.assert_allclose(shift(plot_moments(z, a, r), b - a), plot_moments(z, b, r),
                               rtol=1e-7, atol=1e-6 * np.abs(plot_moments(z, b, r)).max())


def test_kurtosis_of_a_gaussian_and_of_two_clumps() -> None:
    """β₂ = 3 for a Gaussian's Isserlis moments; two equal clumps at ±δ of variance σ²:
    (δ⁴ + 6δ²σ² + 3σ⁴)/(δ² + σ²)² (closed form)."""
    cov = np.array([[[400.0, 100.0], [100.0, 900.0]]])
    m = gaussian_moments(np.array([2.0]), cov)
    assert principal_kurtosis(m, cov)[2][0] == pytest.approx(3.0)
    d, s = 2.0, 1.0
    two = gaussian_moments(np.array([1.0, 1.0]), np.array([np.eye(2) * s**2] * 2))
    both = (shift(two[:1], np.array([[-d, 0.0]])) + shift(two[1:], np.array([[d, 0.0]])))
    c = np.array([[[d**2 + s**2, 0.0], [0.0, s**2]]])
    beta = principal_kurtosis(both, c)[2][0]
    assert beta == pytest.approx((d**4 + 6 * d**2 * s**2 + 3 * s**4) / (d**2 + s**2) ** 2)


def test_state_round_trip_and_hostile_states() -> None:
    rng = np.random.default_rng(1)
    a, b = ForgettingGMMClutter(), ForgettingGMMClutter()
    for k in range(5):
        a.update(_scan(k, _clumps(rng, [(0, 0), (2000, 0)], 20, 200.0)))
    b.set_state(a.get_state())
    z = _clumps(rng, [(0, 0), (2000, 0)], 20, 200.0)
    a.update(_scan(6, z))
    b.update(_scan(6, z))
    q = rng.uniform(-3000, 3000, (50, 2))
    assert np.array_equal(a.intensity(q), b.intensity(q))
    good = a.get_state()
    bad_m = good["moments"].copy()
    bad_m[0, 0] = 0.0
    for key, bad, word in (("moments", bad_m, "weight"), ("moments", np.zeros((2, 14)), "shape"),
                           ("anchors", np.zeros((99, 2)), "shape"),
                           ("looks", -1.0, "looks"), ("bg_mass", -1.0, "bg_mass"),
                           ("box", [1.0, 0.0, 0.0, 1.0], "box"), ("time", np.nan, "time")):
        with pytest.raises(ValueError, match=word):
            ForgettingGMMClutter().set_state({**good, key: bad})
    with pytest.raises(ValueError, match="looks"):  # beyond 1/(1 − γ) with a constant γ
        ForgettingGMMClutter(forgetting=0.7).set_state({**good, "looks": 6.0})
    for kw in ({"forgetting": 0.0}, {"half_life": 0.0}, {"n_components": 0},
               {"split_kurtosis": 3.0}, {"merge_distance": -1.0}, {"max_iter": 0},
               {"reg_covar": 0.0}):
        with pytest.raises(ValueError, match=next(iter(kw))):
            ForgettingGMMClutter(**kw)


def test_a_radar_scale_state_is_restored_and_huge_moments_refused() -> None:
    """Clutter spread over a 250 km radar's reach (σ 60 km): fourth moments ~10²⁰ per
    plot, far beyond a fixed ±1e15 bound — the saved state must restore (a checkpoint of
    ``live --tracker mht-fgmm`` on real coordinates was refused); an infinite or absurd
    moment is still refused."""
    rng = np.random.default_rng(3)
    a, b = ForgettingGMMClutter(), ForgettingGMMClutter()
    for k in range(4):
        a.update(_scan(k, rng.normal((120e3, -80e3), 60e3, (200, 2))))
    good = a.get_state()
    assert np.abs(good["moments"]).max() > 1e15
    b.set_state(good)
    q = rng.uniform(-250e3, 250e3, (50, 2))
    assert np.array_equal(a.intensity(q), b.intensity(q))
    w = good["moments"][0, 0]
    for bad_value in (np.inf, np.nan, 1e60, 1.01 * w * 2e9**4):  # last: beyond M_00·d_max⁴
        bad = good["moments"].copy()
        bad[0, 10] = bad_value  # a fourth-order column
        with pytest.raises(ValueError, match="moments"):
            ForgettingGMMClutter().set_state({**good, "moments": bad})


def test_forget_takes_the_tracks_plots_out_of_count_and_statistics() -> None:
    """``M̂`` after forgetting m of the last scan's n plots is ``(γC + n − m)/N``; the
    statistics lose exactly the responsibilities of those plots (total mass)."""
    rng = np.random.default_rng(9)
    e = ForgettingGMMClutter(forgetting=0.5, split_kurtosis=0.0)
    a = _clumps(rng, [(0, 0), (3000, 0)], 20, 200.0)
    b = _clumps(rng, [(0, 0), (3000, 0)], 20, 200.0)
    e.update(_scan(0, a))
    e.update(_scan(1, b))
    mass = e.moments_[:, 0].sum() + e.bg_mass_
    used = np.arange(len(b)) % 4 == 0
    e.forget(used)
    assert e.count_ == pytest.approx((0.5 * 40 + 40 - used.sum()) / 1.5)
    assert e.moments_[:, 0].sum() + e.bg_mass_ == pytest.approx(mass - used.sum())
    assert np.isfinite(e.intensity(b)).all()
    e.forget(used)  # once per scan: a second call changes nothing
    assert e.count_ == pytest.approx((0.5 * 40 + 40 - used.sum()) / 1.5)


def test_a_half_life_is_the_per_scan_factor_of_the_scans_spacing() -> None:
    """With scans ``Δt`` apart, ``half_life = h`` discounts exactly as the constant
    ``forgetting = 2^(−Δt/h)``: the same statistics, count and intensity."""
    rng = np.random.default_rng(3)
    dt, h = 4.0, 10.0
    a = ForgettingGMMClutter(half_life=h)
    b = ForgettingGMMClutter(forgetting=2.0 ** (-dt / h))
    for k in range(8):
        z = _clumps(rng, [(0, 0), (3000, 1000 + 100 * k)], 25, 300.0)
        for est in (a, b):
            est.update(Scan(k, k * dt, z, np.zeros(len(z), np.int64), np.arange(len(z))))
    np.testing.assert_allclose(a.moments_, b.moments_, rtol=1e-12, atol=1e-9)
    assert a.count_ == pytest.approx(b.count_, rel=1e-12)
    q = rng.uniform(-3000, 5000, (40, 2))
    np.testing.assert_allclose(a.intensity(q), b.intensity(q), rtol=1e-10)
