"""The shortcuts of a scan's update give the floats of the plain calls, bit for bit."""

import numpy as np
import pytest

from mhtrack.clutter import AGMMClutter, GMMClutter
from mhtrack.clutter.em import fit_em
from mhtrack.clutter.seeding import kmeanspp_centres, mixture_from_centres
from mhtrack.models.clutter import Region
from mhtrack.records import Scan


def same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def _scan_plots(rng: np.random.Generator, k: int) -> np.ndarray:
    n = int(rng.integers(1, 60)) if k % 3 else 1  # one-plot scans too
    z = rng.uniform(-3000.0, 3000.0, (n, 2))
    m = int(rng.integers(0, 15))
    return np.concatenate((z, rng.normal((600.0, -900.0), 80.0, (m, 2))))


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("cls", [AGMMClutter, GMMClutter])
def test_intensity_at_the_scan_plots_is_the_density_of_the_fit(cls: type, seed: int) -> None:
    """κ̂ at the scan's own plots comes from the fit's ``log c``: the floats of
    ``M̂ · mixture.pdf(z)``; other positions, or the scan's with a subsampled pool or a
    fixed region the plots leave, still agree."""
    rng = np.random.default_rng(seed)
    kw = {"region": Region(-2000.0, 2000.0, -2000.0, 2000.0)} if seed == 5 else {}
    est = cls(window=3, max_points=40 if seed == 4 else 2000, **kw)
    shortcuts = 0
    for k in range(12):
        z = _scan_plots(rng, k)
        before = est.n_subsampled_
        est.update(Scan.from_positions(k, float(k), z), None)
        subsampled = est.n_subsampled_ > before
        assert (est._scan_log_c is None) == subsampled  # a subsampled pool: no shortcut
        shortcuts += not subsampled
        assert same(est.intensity(z), est.count_ * est.mixture_.pdf(z))
        other = z + 1.0
        assert same(est.intensity(other), est.count_ * est.mixture_.pdf(other))
    assert shortcuts >= 4


def test_intensity_follows_a_mixture_set_by_hand() -> None:
    """A ``mixture_`` replaced after the fit (another estimator's) is the one ``κ̂``
    reads, also at the scan's own plots: the fit's cached ``log c`` is not its."""
    rng = np.random.default_rng(3)
    a, b = AGMMClutter(window=3), AGMMClutter(window=3)
    for k in range(4):
        a.update(Scan.from_positions(k, float(k), _scan_plots(rng, k)), None)
    z = _scan_plots(rng, 9)
    b.update(Scan.from_positions(0, 0.0, z), None)
    assert b._scan_log_c is not None  # the shortcut would otherwise answer
    b.mixture_ = a.mixture_
    assert same(b.intensity(z), b.count_ * a.mixture_.pdf(z))
    assert not same(b.intensity(z), b.count_ * np.exp(b._scan_log_c[1]))


@pytest.mark.parametrize("seed", range(8))
def test_fit_em_log_density_is_log_pdf(seed: int) -> None:
    """``EMResult.log_density`` is ``mixture.log_pdf(z)`` bit for bit, also after
    deletions and for a plot outside the background's box."""
    rng = np.random.default_rng(seed)
    z = np.concatenate((rng.uniform(-4000, 4000, (150, 2)), rng.normal(800, 150, (40, 2))))
    box = (-4500.0, 4500.0, -4500.0, 4500.0) if seed % 4 else (-3000.0, 4500.0, -4500.0, 4500.0)
    init = mixture_from_centres(z, kmeanspp_centres(z, 8, np.random.default_rng(seed)),
                                reg_covar=100.0, background_box=box, background_weight=0.05)
    res = fit_em(z, init, reg_covar=100.0, min_points=3.0, bic=seed % 2 == 0,
                 min_contrast=5.0 if seed % 3 else 0.0)
    assert same(res.log_density, res.mixture.log_pdf(z))


@pytest.mark.parametrize("seed", range(10))
def test_starting_mixture_of_any_centres_is_the_plain_one(seed: int) -> None:
    """Centres with no plot, one, two or many (the grouped slices of
    ``mixture_from_centres``): the plain code's floats (``tests/reference/plain_em.py``)."""
    import plain_em

    rng = np.random.default_rng(seed)
    z = rng.normal(0.0, 300.0, (int(rng.integers(1, 30)), 2))
    centres = np.concatenate((z[rng.choice(len(z), min(len(z), 3), replace=False)],
                              rng.normal(0.0, 300.0, (2, 2)), [[1e5, 1e5]]))  # last: no plot
    got = mixture_from_centres(z, centres, reg_covar=100.0)
    want = plain_em.mixture_from_centres(z, centres, reg_covar=100.0)
    for name in ("weights", "means", "covariances"):
        assert same(getattr(got, name), getattr(want, name))


@pytest.mark.parametrize("seed", range(6))
def test_starting_mixture_sums_each_centre_in_plot_order(seed: int) -> None:
    """The means from one pass over all plots (``np.add.at``) against the plain per-centre
    ``mean``: large groups (hundreds to thousands of plots, where a different summation
    order would show), magnitudes far apart and plots at ±0.0, bit for bit."""
    import plain_em

    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(200, 3000))
    z = rng.normal(0.0, 1.0, (n, 2)) * 10.0 ** rng.uniform(-3, 6, (n, 1)) + 1e4
    z[rng.integers(0, n, n // 5)] = -0.0 if seed % 2 else 0.0
    centres = np.concatenate((z[rng.choice(n, 4, replace=False)], [[-0.0, -0.0]]))
    got = mixture_from_centres(z, centres, reg_covar=100.0)
    want = plain_em.mixture_from_centres(z, centres, reg_covar=100.0)
    for name in ("weights", "means", "covariances"):
        assert same(getattr(got, name), getattr(want, name))


@pytest.mark.parametrize("box", [None, (-100.0, 100.0, -100.0, 100.0), (-1e4, 1e4, -1e4, 1e4),
                                 (500.0, 900.0, 500.0, 900.0)])
@pytest.mark.parametrize("n", [0, 1, 7])
def test_log_background_const_is_the_one_value_of_log_background(box, n: int) -> None:
    """``log_background_const``: ``log_background``'s array, and its value when every plot
    has the same one (inside the box, all outside it, no box), else ``None``."""
    from mhtrack.clutter.density import Mixture

    z = np.random.default_rng(n).uniform(-300.0, 300.0, (n, 2))
    mix = Mixture(np.ones(1), np.zeros((1, 2)), np.eye(2)[None], 0.1 if box else 0.0, box)
    with np.errstate(divide="ignore"):
        want = np.where(
            (z[:, 0] >= box[0]) & (z[:, 0] <= box[1]) & (z[:, 1] >= box[2]) & (z[:, 1] <= box[3]),
            -np.log((box[1] - box[0]) * (box[3] - box[2])), -np.inf) if box else np.full(n, -np.inf)
        out, const = mix.log_background_const(z)
    assert same(out, want) and same(mix.log_background(z), want)
    if n and (want == want[0]).all():
        assert same(const, want[0])
    else:
        assert const is None


def test_scan_rngs_hand_out_fresh_generators_of_seed_and_scan() -> None:
    """``ScanRngs.take(seed, u)`` draws as ``default_rng(SeedSequence(seed, spawn_key=(u,)))``
    made then, in any order of scans and seeds, a scan taken twice included."""
    from mhtrack.clutter.seeding import RNG_BATCH, ScanRngs

    rngs = ScanRngs()
    for seed, u in [(0, 0), (0, 3), (0, 1), (0, RNG_BATCH + 2), (0, 3), (7, 3), (0, 2), (7, 3)]:
        got = rngs.take(seed, u).random(4)
        want = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(u,))).random(4)
        assert same(got, want)


@pytest.mark.parametrize("seed", range(6))
def test_lse_t_is_the_plain_formula_with_non_finite_and_huge_maxima(seed: int) -> None:
    """``_lse_t`` skips ``np.where`` when the maxima sum to a finite number: the same floats
    as the plain formula, with columns of −inf, +inf, NaN, and maxima whose sum overflows."""
    from mhtrack.clutter.density import _lse_t
    rng = np.random.default_rng(seed)
    a = rng.normal(0.0, 50.0, (int(rng.integers(1, 10)), 40))
    if seed % 3 == 1:
        a[:, 3] = -np.inf
        a[0, 5], a[-1, 7] = np.inf, np.nan
    elif seed % 3 == 2:
        a[0] = 1e308  # finite maxima, infinite sum
    m = a.max(axis=0)
    m_safe = np.where(np.isfinite(m), m, 0.0)
    with np.errstate(all="ignore"):
        want = np.log(np.exp(a - m_safe).T.copy().sum(axis=1)) + m_safe
        got = _lse_t(a)
    assert same(got, want)
