"""The start-up density (``MHTConfig.startup_density``, :mod:`mhtrack.mht.undetected`):
the maximum-likelihood excess density against closed forms, the PMBM undetected-density
recursion on a hand-worked sequence, and the tracker's first scores by hand."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.clutter import KnownClutter
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.undetected import UndetectedDensity, box_area, excess_density
from mhtrack.records import Scan


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 5000), kappa=st.floats(1e-10, 1e-5), area=st.floats(1e4, 1e11))
def test_uniform_clutter_gives_the_plots_in_excess(n, kappa, area):
    # Σ u/(κ+u) = uV with one κ: n/(κ+u) = V, u = (n − κV)/V; no excess when n ≤ κV.
    u = excess_density(np.full(n, kappa), area)
    want = max((n - kappa * area) / area, 0.0)
    assert u == pytest.approx(want, rel=1e-9, abs=1e-12 * n / area)


def test_two_clutter_levels_solve_the_quadratic():
    # n = 2: 1/(κ1+u) + 1/(κ2+u) = V  ⇔  V u² + (V(κ1+κ2) − 2) u + Vκ1κ2 − (κ1+κ2) = 0.
    k1, k2, V = 1e-7, 4e-7, 1e6
    a, b, c = V, V * (k1 + k2) - 2, V * k1 * k2 - (k1 + k2)
    root = (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)  # = 1.99999975e-6
    assert excess_density(np.array([k1, k2]), V) == pytest.approx(root, rel=1e-10)
    assert excess_density(np.array([k1, k2]), 2 / k1) == 0.0  # Σ 1/κ = 1.25e7 ≤ V


def test_recursion_by_hand():
    # P_D 0.9, λ_v 1e-9, the first scan's excess u = 1e-7 (uniform κ = 1e-7 on V = 1e6:
    # n = 0.2 plots... use n = 2, κ = 1e-7: u = 2e-6 − 1e-7 = 1.9e-6):
    #   D(1|0) = u/0.9, λ_1 = u;  D(1|1) = 0.1 u/0.9;
    #   λ_2 = 0.9 (0.1 u/0.9 + λ) = 0.1 u + 0.9 λ;  λ_3 = 0.01 u + 0.99 λ;
    #   λ_k = 0.1^(k−1) u + (1 − 0.1^(k−1)) λ  →  λ.
    lam, u = 1e-9, 1.9e-6
    und = UndetectedDensity(lam, area=1e6)
    got = [und.first_detection(np.zeros((2, 2)), np.full(2, 1e-7), 0.9)]
    assert got[0] == pytest.approx(u, rel=1e-9)
    assert und.density == pytest.approx(0.1 * u / 0.9, rel=1e-9)
    for _ in range(7):
        got.append(und.first_detection(np.zeros((0, 2)), np.zeros(0), 0.9))
    want = [0.1 ** (k - 1) * u + (1 - 0.1 ** (k - 1)) * lam for k in range(1, 9)]
    assert got == pytest.approx(want, rel=1e-9)


@settings(max_examples=50, deadline=None)
@given(lam=st.floats(1e-12, 1e-5), pd=st.floats(0.05, 0.999), scans=st.integers(1, 30))
def test_a_quiet_start_stays_at_p1s_density(lam, pd, scans):
    # No excess: D(1|0) = λ/P_D, the steady state of D ← (1 − P_D) D + λ: λ_k = λ always.
    und = UndetectedDensity(lam, area=1.0)
    for _ in range(scans):
        assert und.first_detection(np.zeros((1, 2)), np.array([1.0]), pd) == pytest.approx(
            lam, rel=1e-12)


def test_no_plots_at_the_first_scan_waits_for_plots():
    und = UndetectedDensity(1e-9)
    assert und.first_detection(np.zeros((0, 2)), np.zeros(0), 0.9) == 1e-9
    assert und.density is None


def test_box_area():
    assert box_area(np.array([[0.0, 0.0], [1000.0, 10.0], [500.0, 2000.0]])) == 2e6
    assert box_area(np.zeros((3, 2))) == 1.0


def _corners(n_side: int, side: float) -> np.ndarray:
    g = np.linspace(0.0, side, n_side)
    return np.array([[x, y] for x in g for y in g])


def test_tracker_first_scores_by_hand(tmp_path):
    # 16 plots on a grid spanning 1 km × 1 km (V = 1e6), κ = 1e-6: κV = 1 clutter plot,
    # u = (16 − 1)/1e6 = 1.5e-5;  L0 = ln(u P_D/(κ + u)) = ln(1.5e-5 · 0.9 / 1.6e-5).
    cfg = MHTConfig(startup_density=True, imm_sigma_v=0.0)
    trk = MHTTracker(cfg, KnownClutter(1e-6))
    trk.step(Scan.from_positions(1, 0.0, _corners(4, 1000.0)))
    l0 = math.log(1.5e-5 * 0.9 / 1.6e-5)
    assert trk.leaves.score.tolist() == pytest.approx([l0] * 16, rel=1e-9)
    # Off (P1): L0 = ln(λ_v P_D/(κ + λ_v)) with λ_v = 1e-7.
    p1 = MHTTracker(MHTConfig(imm_sigma_v=0.0), KnownClutter(1e-6))
    p1.step(Scan.from_positions(1, 0.0, _corners(4, 1000.0)))
    assert p1.leaves.score.tolist() == pytest.approx([math.log(0.9e-7 / 1.1e-6)] * 16)
    # Saved and restored: D(1|1) = 0.1 u/0.9 goes with the state; scan 2 scores alike.
    trk.save(tmp_path / "s.npz")
    back = MHTTracker.load(tmp_path / "s.npz")
    assert back.birth.undetected.density == trk.birth.undetected.density
    scan2 = Scan.from_positions(2, 1.0, _corners(3, 1000.0) + 20.0)
    a, b = trk.step(scan2), back.step(scan2)
    assert np.array_equal(trk.leaves.score, back.leaves.score)
    assert len(a) == len(b)
    # Scan 2's births: λ_2 = 0.9 (0.1 u/0.9 + λ_v) = 0.1 u + 0.9 λ_v.
    lam2 = 0.1 * 1.5e-5 + 0.9 * 1e-7
    born = (trk.leaves.n_updates == 1) & (trk.leaves.window[:, -1] >= 0)  # plot at scan 2
    assert born.sum() == 9
    assert trk.leaves.score[born] == pytest.approx(math.log(lam2 * 0.9 / (1e-6 + lam2)))


def test_only_with_every_plot_births():
    with pytest.raises(ValueError, match="startup_density"):
        MHTConfig(startup_density=True, birth="logic")


def test_hostile_saved_density_is_rejected():
    und = UndetectedDensity(1e-9)
    for bad in (np.array(-1.0), np.array([1.0]), np.array(np.nan), np.array(1)):
        with pytest.raises(ValueError, match="undetected_density"):
            und.set_arrays({"undetected_density": bad})
