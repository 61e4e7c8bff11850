"""Track score arithmetic (P1 eqs. 4, 5; Blackman & Popoli §6.2) and Wald's SPRT."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from mhtrack.clutter import KnownClutter
from mhtrack.mht import (
    MHTConfig,
    MHTTracker,
    birth_score,
    miss_increment,
    sprt_thresholds,
    update_increment,
)
from mhtrack.records import Scan


def test_one_track_two_scans_by_hand():
    # P_D = 0.9, λ_v = 1e-7, κ = 1e-8, σw = 100 (R = 1e4 I), v_max = 300, σv = 10, T = 1.
    # Scan 1: one plot at (0, 0) starts a tree with
    #   L0 = ln(λ_v P_D / (κ + λ_v)) = ln(0.9e-7 / 1.1e-7) = ln(9/11) = −0.200671.
    # Scan 2: plot at (100, 0). Predicted position variance per axis
    #   = R (1e4) + T²·(v_max/2)² (22 500) + σv²·T⁴/4 (25) = 32 525, cross terms 0,
    #   S = 32 525 + 1e4 = 42 525 I;  d² = 100² / 42 525 = 0.235156;
    #   ln p(z|T) = −½(d² + 2 ln 42 525) − ln 2π = −½(0.235156 + 21.315695) − 1.837877
    #             = −12.613302;
    #   ΔL = ln p + ln 0.9 − ln(1e-8 + 1e-7) = −12.613302 − 0.105361 + 16.022785 = 3.304123;
    #   L(2) = −0.200671 + 3.304123 = 3.103452.
    # Miss branch: L0 + ln(1 − 0.9) = −0.200671 − 2.302585 = −2.503256.
    # The scan-2 plot also starts its own tree at L0 = −0.200671.
    l0 = math.log(9 / 11)
    trk = MHTTracker(MHTConfig(imm_sigma_v=0.0), KnownClutter(1e-8))
    trk.step(Scan.from_positions(1, 0.0, [[0.0, 0.0]]))
    assert trk.leaves.score.tolist() == pytest.approx([l0], abs=1e-9)
    trk.step(Scan.from_positions(2, 1.0, [[100.0, 0.0]]))
    L = trk.leaves
    first = L.tree == L.tree.min()
    got = sorted(L.score[first].tolist())
    assert got == pytest.approx([-2.503256, 3.103452], abs=1e-6)
    assert L.score[~first].tolist() == pytest.approx([l0], abs=1e-9)
    # the updated leaf is the one that used the plot (row 0 of scan 2)
    upd = first & (L.window[:, -1] == 0)
    assert L.score[upd].item() == pytest.approx(3.103452, abs=1e-6)
    assert L.n_updates[upd].item() == 2


def test_imm_two_scans_by_hand():
    # The same two plots with the default IMM: quiet model σ = 1, manoeuvre σ = 10, equal
    # initial probabilities, both models at the one-point state. Mixing leaves the common
    # state unchanged; per axis the predicted position variances are
    #   R + T²(v_max/2)² + σ²T⁴/4 = 32 500.25 (quiet) and 32 525 (manoeuvre),
    # and the score uses ln(½ N(ν; 0, S_q) + ½ N(ν; 0, S_m)) (Blom & Bar-Shalom 1988).
    def lnN(S: float) -> float:  # ν = (100, 0), S = s·I
        return -0.5 * (100.0**2 / S + 2 * math.log(S)) - math.log(2 * math.pi)

    lq, lm = lnN(32_500.25 + 1e4), lnN(32_525.0 + 1e4)
    mix = math.log(0.5 * math.exp(lq) + 0.5 * math.exp(lm))
    expected = math.log(9 / 11) + mix + math.log(0.9) - math.log(1e-8 + 1e-7)
    cfg = MHTConfig(imm_sigma_v=1.0)
    trk = MHTTracker(cfg, KnownClutter(1e-8))
    trk.step(Scan.from_positions(1, 0.0, [[0.0, 0.0]]))
    trk.step(Scan.from_positions(2, 1.0, [[100.0, 0.0]]))
    L = trk.leaves
    upd = (L.tree == L.tree.min()) & (L.window[:, -1] == 0)
    assert L.score[upd].item() == pytest.approx(expected, abs=1e-9)
    # posterior model probabilities ∝ ½ exp(l_j), state = their mixture
    wq = 1.0 / (1.0 + math.exp(lm - lq))
    assert L.mu[upd][0].tolist() == pytest.approx([wq, 1.0 - wq], abs=1e-12)
    assert L.x[upd][0] == pytest.approx(L.mu[upd][0] @ L.xm[upd][0], abs=1e-9)


def test_increment_functions():
    assert miss_increment(0.9) == pytest.approx(math.log(0.1))
    # exact form with a gate probability: ln(1 − P_D P_G)
    assert miss_increment(0.9, 0.99) == pytest.approx(math.log(1 - 0.891))
    dl = update_increment(np.array([-12.0]), np.array([1e-9]), 0.9, 1e-7)
    assert dl.item() == pytest.approx(-12.0 + math.log(0.9) - math.log(1.01e-7))
    assert birth_score(np.array([6.25e-7]), 0.9, 1e-7).item() == pytest.approx(
        math.log(0.9e-7 / 7.25e-7)
    )


def test_miss_option_changes_the_miss_score():
    cfg = MHTConfig(miss_uses_gate_probability=True, gate_probability=0.99)
    trk = MHTTracker(cfg, KnownClutter(1e-8))
    trk.step(Scan.from_positions(1, 0.0, [[0.0, 0.0]]))
    trk.step(Scan.from_positions(2, 1.0, np.zeros((0, 2))))
    assert trk.leaves.score.item() == pytest.approx(math.log(9 / 11) + math.log(1 - 0.9 * 0.99))


def test_sprt_thresholds_are_walds():
    up, down = sprt_thresholds(0.01, 1e-4)
    assert up == pytest.approx(math.log((1 - 1e-4) / 0.01))  # 4.6042
    assert down == pytest.approx(math.log(1e-4 / (1 - 0.01)))  # -9.2003
    trk = MHTTracker(MHTConfig(alpha=0.05, beta=0.2))
    assert trk.sprt.confirm_threshold == pytest.approx(math.log(0.8 / 0.05))
    assert trk.sprt.delete_threshold == pytest.approx(math.log(0.2 / 0.95))
    with pytest.raises(ValueError):
        sprt_thresholds(0.6, 0.5)


def _clean_target_confirmation_scan(kappa: float, seed: int) -> tuple[int, MHTTracker]:
    """Scan at which a lone target (100 m/s, σ = 100 m, P_D = 1) is first reported."""
    trk = MHTTracker(MHTConfig(), KnownClutter(kappa))
    rng = np.random.default_rng(seed)
    first = None
    for k in range(1, 16):
        z = np.array([[100.0 * k, 0.0]]) + rng.normal(0, 100, (1, 2))
        if len(trk.step(Scan.from_positions(k, float(k), z))) and first is None:
            first = k
    return first, trk


def test_clean_target_confirms_within_a_few_scans():
    # sparse clutter (κ = 1e-8): L0 = ln(9/11) = −0.2, then ~+3.5 per plot
    scans = [_clean_target_confirmation_scan(1e-8, seed)[0] for seed in range(10)]
    assert max(scans) <= 4
    # the true density of 10 clutter plots/scan over 64 km²: L0 = −1.05, ~+2 per plot
    scans = [_clean_target_confirmation_scan(1.5625e-7, seed)[0] for seed in range(10)]
    assert np.median(scans) <= 5 and max(scans) <= 7


def test_track_is_deleted_after_consecutive_misses():
    _, trk = _clean_target_confirmation_scan(1e-8, 0)
    assert trk.leaves.track.max() == 0
    # four misses: 4 ln 0.1 = −9.21 ≤ ln(β/(1−α)) = −9.20 deletes the leaf; three do not
    for k in range(16, 19):
        out = trk.step(Scan.from_positions(k, float(k), np.zeros((0, 2))))
    assert out.track_id.tolist() == [0]
    out = trk.step(Scan.from_positions(19, 19.0, np.zeros((0, 2))))
    assert len(out) == 0
    assert len(trk.leaves) == 0


@settings(max_examples=300, deadline=None)
@given(log_kappa=st.floats(-32.0, -5.0), log_g=st.floats(-30.0, -5.0))
def test_continuation_against_miss_plus_birth_does_not_depend_on_clutter(log_kappa, log_g):
    # A plot z with innovation likelihood g either updates track T, or starts a new tree
    # while T misses. Both alternatives are scored against the same reference density
    # κ + λv (P1 eq. 15), so the update wins iff g > λv (1 − P_D), whatever κ is. With a
    # birth score against κ alone, ln(λv P_D/κ), a small κ made the new tree win and
    # tracks coast beside their own plots.
    pd, lv = 0.9, 1e-7
    assume(abs(log_g - math.log(lv * (1 - pd))) > 1e-6)
    kappa = np.array([math.exp(log_kappa)])
    upd = update_increment(np.array([log_g]), kappa, pd, lv).item()
    alt = miss_increment(pd) + birth_score(kappa, pd, lv).item()
    assert (upd > alt) == (log_g > math.log(lv * (1 - pd)))


def test_lone_target_in_near_empty_clutter_keeps_its_plots():
    # κ = 1e-12 per m² (a clutter-free sky): once confirmed, the track takes the target's
    # plot at every scan and no second track appears.
    trk = MHTTracker(MHTConfig(), KnownClutter(1e-12))
    rng = np.random.default_rng(0)
    rows = []
    for k in range(1, 21):
        z = np.array([[100.0 * k, 0.0]]) + rng.normal(0, 100, (1, 2))
        rows.append(trk.step(Scan.from_positions(k, float(k), z)))
    late = [r for r in rows[5:]]
    assert all(r.track_id.tolist() == [0] for r in late)
    assert all(r.plot.tolist() == [0] for r in late)


def test_update_increment_per_plot_equals_per_pair():
    """``kappa`` per plot with each pair's ``plot`` gives the floats of ``kappa`` taken per
    pair first."""
    rng = np.random.default_rng(4)
    kappa = 10.0 ** rng.uniform(-12, -6, 30)
    plot = rng.integers(0, 30, 500)
    ll = rng.normal(-10, 3, 500)
    want = update_increment(ll, kappa[plot], 0.9, 1e-7)
    assert update_increment(ll, kappa, 0.9, 1e-7, plot).tobytes() == want.tobytes()
