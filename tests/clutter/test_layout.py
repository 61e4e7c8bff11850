"""The component-major EM gives the floats of the plain plot-major code, bit for bit
(``tests/reference/plain_em.py``, the code of main 46050f2), on random fits of every kind."""

import numpy as np
import plain_em
import pytest

from mhtrack.clutter.agmm import keep_mass
from mhtrack.clutter.density import Mixture, plot_sums
from mhtrack.clutter.em import (
    e_step,
    fit_em,
    gaussian_log_pdf,
    logsumexp_rows,
    m_step,
    mahalanobis2,
    removal_gain,
)
from mhtrack.clutter.gmm import keep_above
from mhtrack.clutter.seeding import kmeanspp_centres, mixture_from_centres


def same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("seed", range(4))
def test_plot_sums_are_numpy_column_sums(seed: int) -> None:
    """Per column of a row-major (n, w) array: NumPy's own ``sum(axis=0)``, zeros' signs
    included, also for several arrays side by side and for one column (pairwise)."""
    rng = np.random.default_rng(seed)
    for n in (0, 1, 2, 7, 8, 9, 130, 1000):
        for w in (1, 2, 3, 8, 11):
            a = rng.standard_normal((n, w)) * 10.0 ** rng.integers(-8, 8, (n, w))
            a[rng.random((n, w)) < 0.2] = 0.0
            a[rng.random((n, w)) < 0.2] = -0.0
            if seed == 3:
                a[:] = -0.0
            assert same(plot_sums(np.ascontiguousarray(a.T), w), a.sum(axis=0))
            b = np.ascontiguousarray(a[:, ::-1])
            both = np.concatenate((a.T, b.T))  # two (n, w) arrays as one block of rows
            assert same(plot_sums(both, w), np.concatenate((a.sum(axis=0), b.sum(axis=0))))


def _case(seed: int):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 400))
    z = np.concatenate((rng.uniform(-4000, 4000, (n, 2)),
                        rng.normal([800.0, -300.0], 120.0, (int(rng.integers(0, 60)), 2))))
    box = None if seed % 5 == 4 else (-4500.0, 4500.0, -4500.0, 4500.0)
    if seed % 7 == 3:
        box = (-3000.0, 3000.0, -3000.0, 3000.0)  # some plots outside the background's box
    k = int(rng.integers(1, 11))
    reg = (1e-6, 100.0)[seed % 2]
    init = mixture_from_centres(z, kmeanspp_centres(z, k, np.random.default_rng(seed)),
                                reg_covar=reg, background_box=box,
                                background_weight=0.0 if box is None else 0.05)
    kw = dict(reg_covar=reg, min_points=(0.0, 3.0)[seed % 3 > 0],
              background_floor=(0.0, 0.01)[seed % 2], min_contrast=(0.0, 5.0)[seed % 4 > 1],
              bic=seed % 3 != 1,
              prune=(None, lambda w: keep_mass(w), lambda w: keep_above(w, 0.05))[seed % 3],
              sample_weight=rng.uniform(0.2, 2.0, len(z)) if seed % 6 == 5 else None)
    return z, init, kw


@pytest.mark.parametrize("seed", range(60))
def test_fit_em_matches_the_plain_code_bit_for_bit(seed: int) -> None:
    z, init, kw = _case(seed)
    mix, ll, n_iter, converged, n_pruned = plain_em.fit_em(z, init, **kw)
    got = fit_em(z, init, **kw)
    assert (got.n_iter, got.converged, got.n_pruned) == (n_iter, converged, n_pruned)
    assert same(got.log_likelihood, ll)
    for name in ("weights", "means", "covariances"):
        assert same(getattr(got.mixture, name), getattr(mix, name))
    assert same(got.mixture.background_weight, mix.background_weight)


@pytest.mark.parametrize("seed", range(20))
def test_density_pieces_match_the_plain_code_bit_for_bit(seed: int) -> None:
    z, mix, kw = _case(seed)
    sw = kw["sample_weight"]
    q = np.random.default_rng(seed).uniform(-6000, 6000, (int(seed * 7 % 50) + 1, 2))
    for pts in (z, q):
        wlp = plain_em.weighted_log_prob(mix, pts)
        assert same(mix.weighted_log_prob(pts), wlp)
        assert same(mix.log_pdf(pts), plain_em.logsumexp_rows(wlp))
        assert same(mix.pdf(pts), np.exp(plain_em.logsumexp_rows(wlp)))
        assert same(logsumexp_rows(wlp), plain_em.logsumexp_rows(wlp))
        assert same(mix.log_background(pts), plain_em.log_background(mix, pts))
        assert same(gaussian_log_pdf(pts, mix.means, mix.covariances),
                    plain_em.gaussian_log_pdf(pts, mix.means, mix.covariances))
        assert same(mahalanobis2(pts, mix.means, mix.covariances),
                    plain_em.maha_det(pts, mix.means, mix.covariances)[0])
    ll, resp = e_step(z, mix, sw)
    wlp = plain_em.weighted_log_prob(mix, z)
    norm = plain_em.logsumexp_rows(wlp)
    assert same(ll, plain_em.mean_ll(norm, sw))
    assert same(resp, np.exp(wlp - norm[:, None]))
    got, nk = m_step(z, resp, mix.background_box, sample_weight=sw, reg_covar=kw["reg_covar"],
                     background_floor=kw["background_floor"])
    want, nk_want = plain_em.m_step(z, resp, mix.background_box, sw, kw["reg_covar"],
                                    kw["background_floor"])
    assert same(nk, nk_want) and same(got.weights, want.weights)
    assert same(got.means, want.means) and same(got.covariances, want.covariances)
    if mix.background_box is not None:
        assert same(removal_gain(z, mix, sw), plain_em.removal_gain(z, mix, sw))


def test_init_log_pdf_is_only_a_shortcut() -> None:
    z, init, kw = _case(2)
    from mhtrack.clutter.density import log_pdf_t, maha_det_t, offsets_t, plots_t

    glp = log_pdf_t(*maha_det_t(*offsets_t(plots_t(z), init.means), init.covariances))
    a, b = fit_em(z, init, **kw), fit_em(z, init, init_log_pdf=glp, **kw)
    assert a.log_likelihood == b.log_likelihood and same(a.mixture.means, b.mixture.means)
    assert same(glp.T, plain_em.gaussian_log_pdf(z, init.means, init.covariances))


def test_mixture_is_still_importable_from_em() -> None:
    from mhtrack.clutter import em

    assert em.Mixture is Mixture


@pytest.mark.parametrize("seed", range(20))
def test_seeding_matches_the_plain_code_bit_for_bit(seed: int) -> None:
    rng = np.random.default_rng(seed)
    z = rng.normal(0.0, 500.0, (int(rng.integers(1, 40)), 2))
    if seed % 4 == 3:
        z = np.repeat(z[:2], 4, axis=0)  # duplicate plots: D² reaches 0
    existing = rng.normal(0.0, 500.0, (3, 2)) if seed % 2 else None
    k = int(rng.integers(1, 9))
    got = kmeanspp_centres(z, k, np.random.default_rng(seed), existing=existing)
    want = plain_em.kmeanspp_centres(z, k, np.random.default_rng(seed), existing=existing)
    assert same(got, want)
    box = (-5000.0, 5000.0, -5000.0, 5000.0)
    a = mixture_from_centres(z, got, reg_covar=100.0, background_box=box,
                             background_weight=0.05)
    b = plain_em.mixture_from_centres(z, want, reg_covar=100.0, background_box=box,
                                      background_weight=0.05)
    for name in ("weights", "means", "covariances"):
        assert same(getattr(a, name), getattr(b, name))
