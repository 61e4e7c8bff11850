"""The EM core against scikit-learn and against hand-checkable facts."""

import warnings

import numpy as np
import pytest

from mhtrack.clutter.em import (
    Mixture,
    e_step,
    fit_em,
    gaussian_log_pdf,
    logsumexp_rows,
    m_step,
    removal_gain,
)
from mhtrack.clutter.seeding import kmeanspp_centres, mixture_from_centres


def _three_blobs(seed: int = 0, n: int = 150) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    means = np.array([[-2000.0, 1000.0], [700.0, 700.0], [0.0, -1500.0]])
    covs = [np.diag([900.0, 400.0]), np.array([[2500.0, 1200.0], [1200.0, 1600.0]]),
            np.diag([100.0, 6400.0])]
    z = np.concatenate([rng.multivariate_normal(m, c, n) for m, c in zip(means, covs,
                                                                           strict=True)])
    return z, means


@pytest.mark.parametrize(("k", "n_iter", "seed"), [(1, 3, 0), (3, 1, 1), (4, 40, 2), (6, 100, 3)])
def test_log_likelihood_matches_sklearn(k: int, n_iter: int, seed: int) -> None:
    GaussianMixture = pytest.importorskip(  # the reference (dev extra), not a dependency
        "sklearn.mixture", reason="scikit-learn (dev extra) not installed").GaussianMixture
    z, _ = _three_blobs(seed)
    init = mixture_from_centres(z, kmeanspp_centres(z, k, np.random.default_rng(seed)),
                                reg_covar=1e-6)
    ours = fit_em(z, init, reg_covar=1e-6, tol=0.0, max_iter=n_iter)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ConvergenceWarning: we ask for a fixed n_iter
        ref = GaussianMixture(
            k, covariance_type="full", weights_init=init.weights, means_init=init.means,
            precisions_init=np.linalg.inv(init.covariances), reg_covar=1e-6, tol=1e-300,
            max_iter=n_iter,
        ).fit(z)
    assert ours.n_iter == n_iter
    assert abs(ours.log_likelihood - ref.score(z)) < 1e-6
    order = np.lexsort(ours.mixture.means.T)
    ref_order = np.lexsort(ref.means_.T)
    np.testing.assert_allclose(ours.mixture.means[order], ref.means_[ref_order], atol=1e-6)
    np.testing.assert_allclose(ours.mixture.weights[order], ref.weights_[ref_order], atol=1e-9)


def test_gaussian_log_pdf_matches_scipy() -> None:
    from scipy.stats import multivariate_normal

    rng = np.random.default_rng(5)
    z = rng.normal(size=(20, 2)) * 300
    means = rng.normal(size=(3, 2)) * 100
    covs = np.array([[[900.0, 300.0], [300.0, 400.0]], [[1e4, -5e3], [-5e3, 1e4]],
                     [[25.0, 0.0], [0.0, 4e4]]])
    ref = np.column_stack([multivariate_normal(m, c).logpdf(z) for m, c in
                           zip(means, covs, strict=True)])
    np.testing.assert_allclose(gaussian_log_pdf(z, means, covs), ref, rtol=1e-10)


def test_recovers_well_separated_means() -> None:
    z, truth = _three_blobs(7, n=300)
    init = mixture_from_centres(z, kmeanspp_centres(z, 3, np.random.default_rng(0)),
                                reg_covar=1e-6)
    res = fit_em(z, init, reg_covar=1e-6, tol=1e-8, max_iter=300)
    assert res.converged
    got = res.mixture.means[np.argsort(res.mixture.means[:, 0])]
    want = truth[np.argsort(truth[:, 0])]
    np.testing.assert_allclose(got, want, atol=15.0)  # ~3 standard errors of 300 plots
    np.testing.assert_allclose(np.sort(res.mixture.weights), [1 / 3] * 3, atol=1e-6)


def test_integer_sample_weights_equal_repeated_plots() -> None:
    z, _ = _three_blobs(3, n=40)
    w = np.random.default_rng(0).integers(1, 4, len(z)).astype(float)
    init = mixture_from_centres(z, z[[0, 50, 100]], reg_covar=1.0)
    a = fit_em(z, init, sample_weight=w, reg_covar=1.0, tol=0.0, max_iter=20)
    b = fit_em(np.repeat(z, w.astype(int), axis=0), init, reg_covar=1.0, tol=0.0, max_iter=20)
    assert a.log_likelihood == pytest.approx(b.log_likelihood, abs=1e-9)
    np.testing.assert_allclose(a.mixture.covariances, b.mixture.covariances, rtol=1e-9)


def test_responsibilities_finite_far_from_every_component() -> None:
    mix = Mixture(np.array([0.5, 0.5]), np.array([[0.0, 0.0], [10.0, 0.0]]),
                  np.repeat(np.eye(2)[None], 2, axis=0))
    z = np.array([[1e7, 1e7], [5.0, 0.0]])  # log-densities ~ -1e14: ratio of exps is 0/0
    ll, resp = e_step(z, mix)
    assert np.isfinite(resp).all() and np.isfinite(ll)
    np.testing.assert_allclose(resp.sum(axis=1), 1.0)
    assert resp[0, 2] == pytest.approx(1.0)  # the nearer component takes the far plot
    assert logsumexp_rows(np.full((1, 3), -np.inf))[0] == -np.inf


def test_background_absorbs_uniform_plots_and_respects_floor() -> None:
    rng = np.random.default_rng(2)
    clump = rng.normal([0.0, 0.0], 30.0, (200, 2))
    spread = rng.uniform(-4000, 4000, (200, 2))
    z = np.concatenate((clump, spread))
    box = (-4000.0, 4000.0, -4000.0, 4000.0)
    init = mixture_from_centres(z, np.array([[0.0, 0.0]]), reg_covar=100.0,
                                background_box=box, background_weight=0.05)
    res = fit_em(z, init, reg_covar=100.0, tol=1e-6, max_iter=500, min_points=3.0)
    assert res.mixture.background_weight == pytest.approx(0.5, abs=0.05)
    # the constrained M-step: with few uniform plots pi0 stays at the floor
    _, resp = e_step(clump, init)
    mix, _ = m_step(clump, resp, box, reg_covar=100.0, background_floor=0.2)
    assert mix.background_weight == pytest.approx(0.2)
    assert mix.weights.sum() == pytest.approx(0.8)


def test_kmeanspp_identical_plots_give_one_centre() -> None:
    z = np.full((50, 2), 123.0)
    c = kmeanspp_centres(z, 8, np.random.default_rng(0))
    assert c.shape == (1, 2)
    mix = mixture_from_centres(z, c, reg_covar=4.0)
    np.testing.assert_allclose(mix.covariances[0], 4.0 * np.eye(2))


def test_pdf_fast_path_equals_log_path() -> None:
    z, _ = _three_blobs(1)
    init = mixture_from_centres(z, kmeanspp_centres(z, 5, np.random.default_rng(1)),
                                reg_covar=10.0, background_box=(-3e3, 3e3, -3e3, 3e3),
                                background_weight=0.1)
    g = np.random.default_rng(0).uniform(-3500, 3500, (40_000, 2))  # n*K above the cut
    np.testing.assert_allclose(init.pdf(g), np.exp(init.log_pdf(g)), rtol=1e-12, atol=1e-300)


def test_removal_gain_is_the_log_likelihood_lost() -> None:
    """``removal_gain`` equals the difference of two log-likelihood sums computed with the
    mixture as is and with component ``j``'s weight given to the background."""
    rng = np.random.default_rng(4)
    z = np.concatenate((rng.normal([0.0, 0.0], 30.0, (40, 2)),
                        rng.uniform(-4000, 4000, (60, 2))))
    box = (-4000.0, 4000.0, -4000.0, 4000.0)
    mix = Mixture(np.array([0.3, 0.2]), np.array([[0.0, 0.0], [2000.0, -1000.0]]),
                  np.array([np.eye(2) * 900.0, np.eye(2) * 1e6]), 0.5, box)
    w = rng.uniform(0.5, 2.0, len(z))
    gain = removal_gain(z, mix, w)
    for j in range(2):
        keep = np.arange(2) != j
        without = Mixture(mix.weights[keep], mix.means[keep], mix.covariances[keep],
                          mix.background_weight + mix.weights[j], box)
        direct = w @ (mix.log_pdf(z) - without.log_pdf(z))
        assert gain[j] == pytest.approx(direct, rel=1e-10)
    assert gain[0] > 100 > gain[1]  # the clump pays for itself, the broad bump barely


def test_bic_drops_bumps_on_uniform_clutter_and_keeps_clumps() -> None:
    """On uniform plots, EM from 8 k-means++ seeds with the BIC test ends with no
    Gaussian; a tight clump of 15 plots and a broad (σ = 900 m) one of 80 survive it."""
    rng = np.random.default_rng(7)
    box = (-5000.0, 5000.0, -5000.0, 5000.0)
    kw = dict(reg_covar=100.0, tol=1e-4, max_iter=100, min_points=3.0,
              background_floor=0.01, min_contrast=5.0)

    def fit(z, bic):
        centres = kmeanspp_centres(z, 8, np.random.default_rng(0))
        init = mixture_from_centres(z, centres, reg_covar=100.0, background_box=box,
                                    background_weight=0.05)
        return fit_em(z, init, bic=bic, **kw).mixture

    for _ in range(10):
        assert fit(rng.uniform(-5000, 5000, (100, 2)), True).n_components == 0
    uniform = rng.uniform(-5000, 5000, (100, 2))
    clumps = np.concatenate((uniform, rng.normal([1000.0, 1000.0], 40.0, (15, 2)),
                             rng.normal([-2500.0, 2500.0], 900.0, (80, 2))))
    m = fit(clumps, True)
    assert m.n_components >= 2
    near = lambda c: np.min(np.hypot(*(m.means - c).T))  # noqa: E731
    assert near([1000.0, 1000.0]) < 100 and near([-2500.0, 2500.0]) < 500


def _reference_fit(z, mix, *, min_points, bic, tol=1e-4, max_iter=100):
    """EM from the public steps, each recomputing its densities (no reuse)."""
    prev, n_iter = -np.inf, 0
    for n_iter in range(1, max_iter + 1):  # noqa: B007
        ll, resp = e_step(z, mix)
        mix, nk = m_step(z, resp, mix.background_box)
        keep = nk >= min_points
        if bic and mix.n_components:
            keep &= removal_gain(z, mix) >= 3.0 * np.log(len(z))
        deleted = int((~keep).sum())
        if deleted:
            w = mix.weights[keep]
            w = w * (1.0 - mix.background_weight) / w.sum() if w.sum() > 0 else w
            mix = Mixture(w, mix.means[keep], mix.covariances[keep], mix.background_weight,
                          mix.background_box)
        if mix.n_components == 0:
            break
        if not deleted and abs(ll - prev) < tol * abs(prev):
            break
        prev = ll
    return mix, float(np.mean(mix.log_pdf(z))), n_iter


@pytest.mark.parametrize("seed", range(6))
def test_fit_em_reuses_densities_bit_for_bit(seed: int) -> None:
    """``fit_em`` computes each mixture's densities once and keeps the surviving columns
    after a deletion: the same floats as the plain loop over the public steps."""
    rng = np.random.default_rng(seed)
    z = np.concatenate((rng.uniform(-4000, 4000, (300, 2)), rng.normal(800, 150, (60, 2))))
    box = (-4500.0, 4500.0, -4500.0, 4500.0)
    init = mixture_from_centres(z, kmeanspp_centres(z, 8, np.random.default_rng(seed)),
                                reg_covar=1e-6, background_box=box, background_weight=0.05)
    want, ll, n_iter = _reference_fit(z, init, min_points=3.0, bic=seed % 2 == 0)
    got = fit_em(z, init, reg_covar=1e-6, min_points=3.0, bic=seed % 2 == 0)
    assert got.n_iter == n_iter and got.log_likelihood == ll
    assert np.array_equal(got.mixture.means, want.means)
    assert np.array_equal(got.mixture.covariances, want.covariances)
    assert np.array_equal(got.mixture.weights, want.weights)
