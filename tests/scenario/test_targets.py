"""Truth of constant-velocity and recorded targets, against hand values and F^n x0."""

import numpy as np
import pytest

from mhtrack.models.motion import ConstantVelocity
from mhtrack.scenario import RecordedTarget, Target, preset, simulate_truth


def test_crossing_truth_is_F_power_of_initial_state():
    s = preset("crossing")
    truth = simulate_truth(s, seed=1)
    F = ConstantVelocity.F(s.T)
    for t in s.targets:
        rows = truth.target_id == t.id
        scans = truth.scan[rows]
        # alive exactly on birth..death (all inside 1..90 here)
        assert scans.tolist() == list(range(t.birth, t.death + 1))
        states = np.column_stack((truth.x, truth.vx, truth.y, truth.vy))[rows]
        assert np.array_equal(states[0], t.state)  # state at the birth scan
        for n in (1, 7, len(scans) - 1):
            expect = np.linalg.matrix_power(F, n) @ np.asarray(t.state)
            assert np.allclose(states[n], expect, rtol=0, atol=1e-9)


def test_crossing_truth_hand_value():
    # target 2: [-3000, 80, 2000, -100] born at scan 40; ten scans later (T = 1 s):
    # x = -3000 + 10·80 = -2200, y = 2000 - 10·100 = 1000
    truth = simulate_truth(preset("crossing"), seed=0)
    row = (truth.target_id == 2) & (truth.scan == 50)
    assert row.sum() == 1
    assert (truth.x[row][0], truth.y[row][0]) == (-2200.0, 1000.0)
    assert (truth.vx[row][0], truth.vy[row][0]) == (80.0, -100.0)
    assert truth.time[row][0] == 50.0  # t = k·T


def test_truth_sorted_and_clipped_to_scan_range():
    s = preset("crossing", scans=35)  # scans 1..35: target 2 (born 40) never appears
    truth = simulate_truth(s)
    assert set(truth.target_id.tolist()) == {1, 3, 4}
    assert truth.scan.min() == 1 and truth.scan.max() == 35
    key = truth.scan * 100 + truth.target_id
    assert np.all(np.diff(key) > 0)
    assert (truth.target_id == 3).sum() == 35 - 30 + 1


def test_process_noise_matches_discretised_cv_model():
    t = Target(5, (0.0, 10.0, 0.0, -5.0), birth=3, death=2002)
    T, sv = 2.0, 3.0
    _, x = t.states(3, 2002, T, sv, np.random.default_rng(0))
    assert np.array_equal(x[0], t.state)
    dv = np.diff(x[:, [1, 3]], axis=0)  # T·a
    dp = np.diff(x[:, [0, 2]], axis=0)
    # x_{k+1} = F x_k + G a_k with G = [T²/2, T]: p_{k+1} - p_k - T v_k = (T/2)(v_{k+1} - v_k)
    assert np.allclose(dp - T * x[:-1][:, [1, 3]], 0.5 * T * dv, atol=1e-9)
    # v increments ~ N(0, (σv T)²): sample sd within 10 % over 2×1999 draws
    assert dv.std() == pytest.approx(sv * T, rel=0.1)
    assert abs(dv.mean()) < 4 * sv * T / np.sqrt(dv.size)


def test_noisy_truth_needs_a_generator_and_starts_before_range():
    t = Target(0, (0.0, 1.0, 0.0, 1.0), birth=0, death=10)
    with pytest.raises(ValueError, match="random generator"):
        t.states(0, 10, 1.0, sigma_v=1.0)
    a = t.states(5, 10, 1.0, 1.0, np.random.default_rng(4))
    b = t.states(0, 10, 1.0, 1.0, np.random.default_rng(4))
    assert np.array_equal(a[1], b[1][5:])  # same path whatever the window


def test_target_validation():
    with pytest.raises(ValueError, match=r"birth: must be <= death \(5 > 4\)"):
        Target(1, (0, 0, 0, 0), 5, 4)
    with pytest.raises(ValueError, match="state: expected 4 numbers"):
        Target(1, (0, 0, 0), 1, 4)
    with pytest.raises(ValueError, match="id: must be an integer >= 0"):
        Target(-1, (0, 0, 0, 0), 1, 4)
    with pytest.raises(ValueError, match="strictly increasing"):
        RecordedTarget(1, (3, 3), ((0, 0, 0, 0), (0, 0, 0, 0)))


def test_recorded_target_rows_in_range():
    t = RecordedTarget(9, (2, 3, 7), ((1, 0, 2, 0), (3, 0, 4, 0), (5, 0, 6, 0)))
    k, x = t.states_in(3, 10)
    assert k.tolist() == [3, 7] and x[:, 0].tolist() == [3.0, 5.0]
    assert (t.birth, t.death) == (2, 7)
