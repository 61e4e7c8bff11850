"""The per-radar clutter map against closed forms: cell areas, the forgetting average's
mean and variance on stationary Poisson clutter, its response to a step, and its state."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.clutter.radar_map import ClutterMap, birth_scale, cell_areas, smooth_cells
from mhtrack.records import Scan


def _scan(k: int, z: np.ndarray) -> Scan:
    z = np.asarray(z, float).reshape(-1, 2)
    return Scan(k, float(k), z, np.zeros(len(z), np.int64), np.arange(len(z)))


def _uniform_disc(rng: np.random.Generator, n: int, radius: float,
                  site: tuple[float, float]) -> np.ndarray:
    r = radius * np.sqrt(rng.random(n))
    t = 2 * np.pi * rng.random(n)
    return np.column_stack([site[0] + r * np.sin(t), site[1] + r * np.cos(t)])


@given(st.integers(1, 200), st.integers(1, 512), st.floats(1.0, 1e5))
@settings(max_examples=50, deadline=None)
def test_cells_cover_the_disc(n_rings: int, n_az: int, dr: float) -> None:
    """Σ A_c = π (n_r Δr)² (closed form of the disc's area)."""
    total = cell_areas(n_rings, n_az, dr).sum() * n_az
    assert total == pytest.approx(np.pi * (n_rings * dr) ** 2, rel=1e-12)


def test_cells_of_known_positions() -> None:
    """Ring = ⌊r/Δr⌋, sector = ⌊θ n_θ / 2π⌋ with θ clockwise from north about the site."""
    m = ClutterMap(site=(1000.0, -500.0), range_cell=100.0, n_azimuth=4)
    z = np.array([[1000.0, -450.0],   # 50 m north: ring 0, sector 0
                  [1250.0, -500.0],   # 250 m east: ring 2, sector 1
                  [1000.0, -850.0],   # 350 m south: ring 3, sector 2
                  [990.0, -501.0]])   # west-south-west, 10 m: ring 0, sector 2
    ring, sector = m.cells(z)
    assert ring.tolist() == [0, 2, 3, 0]
    assert sector.tolist() == [0, 1, 2, 2]


def test_stationary_poisson_clutter_converges_within_the_forgetting_interval() -> None:
    """Uniform Poisson clutter of known intensity ρ over a disc: after N rotations each
    cell's estimate has mean ρ and variance ρ Σγ^{2m}/(Σγ^m)² / A_c (closed form of the
    forgetting average): ~95 % of cells fall within 1.96 σ, the standardised errors
    have mean ≈ 0 and variance ≈ 1, and the map-wide mean is within 3 σ of ρ."""
    gamma, n_rot, radius, rho = 0.8, 25, 20_000.0, 2e-6
    m = ClutterMap(site=(5e3, 7e3), range_cell=2000.0, n_azimuth=16, forgetting=gamma,
                   smoothing=0, prior_weight=0.0, max_range=radius)
    rng = np.random.default_rng(12)
    lam = rho * np.pi * radius**2  # ≈ 2513 plots per rotation
    for k in range(n_rot):
        m.update(_scan(k, _uniform_disc(rng, rng.poisson(lam), radius, m.site)))
    w = gamma ** np.arange(n_rot)
    factor = (w**2).sum() / w.sum() ** 2
    areas = m.areas()
    sd = np.sqrt(rho * areas * factor) / areas
    zscore = ((m.intensity_map() - rho) / sd).ravel()
    inside = np.mean(np.abs(zscore) < 1.96)
    n = zscore.size  # 160 cells; binomial sd of the fraction ≈ 0.017
    assert abs(inside - 0.95) < 4 * np.sqrt(0.95 * 0.05 / n)
    assert abs(zscore.mean()) < 4 / np.sqrt(n)
    assert 0.6 < zscore.var() < 1.5
    total_sd = np.sqrt(lam * factor) / (np.pi * radius**2)
    assert abs(m.mean_intensity() - rho) < 3 * total_sd


def test_step_change_follows_the_exponential_response() -> None:
    """λ₁ for k₀ rotations, then λ₂: the mean over cells of the estimate follows
    ``λ₂ + (λ₁ − λ₂) γ^m N_k₀ / N_k`` (closed form), within 4 standard errors."""
    gamma, k0, k1, radius = 0.7, 12, 12, 10_000.0
    lam1, lam2 = 400.0, 1600.0  # per rotation over the disc
    m = ClutterMap(range_cell=1000.0, n_azimuth=8, forgetting=gamma, smoothing=0, prior_weight=0.0,
                   max_range=radius)
    rng = np.random.default_rng(3)
    area = np.pi * radius**2
    n_k0 = (1 - gamma**k0) / (1 - gamma)
    for k in range(k0 + k1):
        lam = lam1 if k < k0 else lam2
        m.update(_scan(k, _uniform_disc(rng, rng.poisson(lam), radius, m.site)))
        if k >= k0:
            mm = k - k0 + 1
            n_k = (1 - gamma ** (k + 1)) / (1 - gamma)
            expect = (lam2 + (lam1 - lam2) * gamma**mm * n_k0 / n_k) / area
            got = m.mean_intensity()  # Σ_c S_c / (N_k A): the mean over the cells
            w = gamma ** np.arange(k + 1)[::-1]
            lam_k = np.where(np.arange(k + 1) < k0, lam1, lam2)
            sd = np.sqrt((w**2 * lam_k).sum()) / w.sum() / area
            assert abs(got - expect) < 4 * sd, (k, got, expect)


def test_forget_takes_used_plots_out_and_shrinkage_floors_empty_cells() -> None:
    m = ClutterMap(range_cell=100.0, n_azimuth=4, forgetting=1.0, prior_weight=1.0, smoothing=0)
    z = np.array([[0.0, 50.0], [0.0, 60.0], [0.0, 150.0]])
    m.update(_scan(0, z))
    a0, a1 = cell_areas(2, 4, 100.0)
    rho = 3 / (np.pi * 200.0**2)
    assert m.intensity(z[:1])[0] == pytest.approx((2 / a0 + rho) / 2)
    m.forget(np.array([True, False, False]))
    rho = 2 / (np.pi * 200.0**2)
    assert m.intensity(z[:1])[0] == pytest.approx((1 / a0 + rho) / 2)
    far = m.intensity(np.array([[0.0, -150.0], [5e3, 0.0]]))  # an empty cell, beyond the map
    assert far == pytest.approx([rho / 2, rho / 2])
    assert a1 > a0


def test_outside_gates_source_and_bad_input() -> None:
    m = ClutterMap(source="outside-gates", range_cell=100.0, n_azimuth=1, prior_weight=0,
                   smoothing=0)
    m.update(_scan(0, [[0.0, 10.0], [0.0, 20.0]]), np.array([True, False]))
    assert m.sums_.sum() == 1.0
    with pytest.raises(ValueError, match="in_track_gates has 1"):
        m.update(_scan(1, [[0.0, 10.0], [0.0, 20.0]]), np.array([True]))
    with pytest.raises(ValueError, match="finite"):
        m.update(_scan(1, [[np.nan, 0.0]]))
    for kw, word in (({"forgetting": 0.0}, "forgetting"), ({"forgetting": 1.5}, "forgetting"),
                     ({"range_cell": -1.0}, "range_cell"), ({"n_azimuth": 0}, "n_azimuth"),
                     ({"prior_weight": np.inf}, "prior_weight"), ({"source": "x"}, "source"),
                     ({"max_rings": 0}, "max_rings"), ({"site": (np.nan, 0)}, "site"),
                     ({"birth_scaling": -1.0}, "birth_scaling")):
        with pytest.raises(ValueError, match=word):
            ClutterMap(**kw)


def test_rings_grow_up_to_the_bound() -> None:
    m = ClutterMap(range_cell=100.0, n_azimuth=2, max_rings=5)
    m.update(_scan(0, [[0.0, 250.0], [0.0, 10_000.0]]))
    assert m.n_rings == 3 and m.n_outside_ == 1
    m.update(_scan(1, [[0.0, 450.0]]))
    assert m.n_rings == 5 and m.sums_.shape == (5, 2)


def test_state_round_trip_continues_identically_and_hostile_states_fail() -> None:
    rng = np.random.default_rng(0)
    a, b = ClutterMap(range_cell=300.0), ClutterMap(range_cell=300.0)
    for k in range(4):
        a.update(_scan(k, _uniform_disc(rng, 50, 3000.0, (0.0, 0.0))))
    b.set_state(a.get_state())
    z = _uniform_disc(rng, 60, 3500.0, (0.0, 0.0))
    for m in (a, b):
        m.update(_scan(5, z))
        m.forget(np.arange(60) % 7 == 0)
    q = _uniform_disc(rng, 30, 4000.0, (0.0, 0.0))
    assert np.array_equal(a.intensity(q), b.intensity(q))
    good = a.get_state()
    for key, bad, word in (("sums", -good["sums"] - 1, "negative"),
                           ("sums", np.zeros((3, 7)), "shape"),
                           ("looks", -1.0, "looks"), ("looks", float("nan"), "looks"),
                           ("last", np.array([10**9]), "last"), ("time", np.inf, "time"),
                           ("n_updates", -1, "n_updates"), ("sums", "x", "sums")):
        with pytest.raises(ValueError, match=word):
            ClutterMap(range_cell=300.0).set_state({**good, key: bad})
    with pytest.raises(ValueError, match="looks"):  # beyond 1/(1 − γ) with a constant γ
        ClutterMap(range_cell=300.0, forgetting=0.9).set_state({**good, "looks": 11.0})


def test_birth_scale() -> None:
    """``min(1, ρ̄/κ̂)^β``: 1 at or below the mean, ``(ρ̄/κ̂)^β`` above it."""
    k = np.array([0.0, 1e-7, 4e-7])
    assert birth_scale(k, 2e-7, 1.0).tolist() == [1.0, 1.0, 0.5]
    assert birth_scale(k, 2e-7, 2.0)[2] == pytest.approx(0.25)
    assert birth_scale(k, 0.0, 1.0).tolist() == [1.0, 1.0, 1.0]


@given(st.integers(1, 12), st.integers(1, 16), st.integers(0, 5), st.integers(0, 2**31))
@settings(max_examples=40, deadline=None)
def test_smoothing_keeps_the_total_and_a_constant(rings: int, sectors: int, passes: int,
                                                  seed: int) -> None:
    """``[1, 2, 1]/4`` along both axes (reflecting rings, circular sectors) keeps the
    map's total and leaves a constant map as it is; one pass on a single spike gives the
    kernel's outer product (where the map is at least 3 × 3)."""
    a = np.random.default_rng(seed).poisson(3.0, (rings, sectors)).astype(float)
    out = smooth_cells(a, passes)
    assert out.sum() == pytest.approx(a.sum(), rel=1e-12, abs=1e-12)
    np.testing.assert_allclose(smooth_cells(np.full((rings, sectors), 2.5), passes), 2.5)
    if rings >= 3 and sectors >= 3:
        spike = np.zeros((rings, sectors))
        spike[1, 1] = 16.0
        k = np.array([1.0, 2.0, 1.0])
        np.testing.assert_allclose(smooth_cells(spike, 1)[:3, :3], np.outer(k, k), atol=1e-12)


def test_a_half_life_is_the_per_rotation_factor_of_the_rotations_spacing() -> None:
    """Rotations ``Δt = 6`` s apart with ``half_life = 40`` s give the sums, looks and
    intensities of the constant ``forgetting = 2^(−6/40)``."""
    rng = np.random.default_rng(5)
    a = ClutterMap(range_cell=1000.0, n_azimuth=8, half_life=40.0)
    b = ClutterMap(range_cell=1000.0, n_azimuth=8, forgetting=2.0 ** (-6.0 / 40.0))
    for k in range(10):
        z = _uniform_disc(rng, 30 + 5 * k, 8000.0, (0.0, 0.0))
        for m in (a, b):
            m.update(Scan(k, 6.0 * k, z, np.zeros(len(z), np.int64), np.arange(len(z))))
    np.testing.assert_allclose(a.sums_, b.sums_, rtol=1e-12)
    assert a.looks_ == pytest.approx(b.looks_, rel=1e-12)
    q = _uniform_disc(rng, 30, 9000.0, (0.0, 0.0))
    np.testing.assert_allclose(a.intensity(q), b.intensity(q), rtol=1e-12)
