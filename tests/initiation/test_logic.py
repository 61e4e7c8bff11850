"""3/4 logic and P2's modified logic (angle constraint) on hand-made 4-scan windows."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.build import make_initiator
from mhtrack.initiation import LogicInitiator, Window, leg_angle
from mhtrack.records import Scan

FAR = np.array([[5000.0, -5000.0], [-6000.0, 7000.0]])  # clutter nowhere near


def window(points, R=None, far=True):
    """One scan per entry of ``points`` (a point or None), t = 1, 2, 3, 4 s."""
    scans = []
    for k, p in enumerate(points):
        z = np.zeros((0, 2)) if p is None else np.atleast_2d(np.asarray(p, float))
        if far:
            z = np.vstack((z, FAR + np.array([3000.0 * k, 0.0])))  # 3 km/s: no track
        n = len(z)
        RR = np.broadcast_to(np.eye(2) * 400.0 if R is None else R, (n, 2, 2)).copy()
        scans.append(Scan(k + 1, float(k + 1), z, np.zeros(n, np.int64), np.arange(n), RR))
    return scans


def test_straight_line_is_initiated_by_both_logics_with_exact_state():
    line = [(0.0, 0.0), (200.0, 0.0), (400.0, 0.0), (600.0, 0.0)]
    for method in ("logic", "modified-logic"):
        tr = make_initiator(method).initiate(window(line))
        assert len(tr) == 1, method  # its 3-plot sub-tracks are not reported again
        np.testing.assert_array_equal(tr.plots[0], [0, 0, 0, 0])
        # noise-free line: least squares gives the state at the last scan exactly
        np.testing.assert_allclose(tr.x[0], [600.0, 200.0, 0.0, 0.0], atol=1e-9)
        assert tr.time == 4.0
        # P of a 4-point fit with R = 400 I: var(x_4) = 400·(7/10) (regression at an end)
        np.testing.assert_allclose(tr.P[0, 0, 0], 400.0 * 0.7)
        np.testing.assert_allclose(tr.P[0, 1, 1], 400.0 / 5.0)  # σ²/Σ(t − t̄)²


def test_v_shape_is_rejected_only_by_the_modified_logic():
    # legs (200, 0) then (100, 173.2): turn of 60° by hand (cos α = 100·200/(200·200))
    z3 = (300.0, 100.0 * np.sqrt(3.0))
    pts = [(0.0, 0.0), (200.0, 0.0), z3, None]
    alpha = np.degrees(leg_angle(np.subtract(z3, (200.0, 0.0)), np.array([200.0, 0.0])))
    assert alpha == pytest.approx(60.0)
    # z3 is 200 m from the prediction (400, 0): inside the 300 m gate
    assert np.hypot(400.0 - z3[0], z3[1]) == pytest.approx(200.0)
    plain = make_initiator("logic").initiate(window(pts))
    assert len(plain) == 1
    np.testing.assert_array_equal(plain.plots[0], [0, 0, 0, -1])
    assert len(make_initiator("modified-logic", theta_deg=20).initiate(window(pts))) == 0
    assert len(make_initiator("modified-logic", theta_deg=61).initiate(window(pts))) == 1


def test_small_turn_passes_the_modified_logic():
    turn = np.radians(15.0)
    z3 = (200.0 + 200.0 * np.cos(turn), 200.0 * np.sin(turn))
    tr = make_initiator("modified-logic", theta_deg=20).initiate(
        window([(0.0, 0.0), (200.0, 0.0), z3, None]))
    assert len(tr) == 1


def test_velocity_gate():
    slow = [(0.0, 0.0), (20.0, 0.0), (40.0, 0.0), (60.0, 0.0)]  # 20 m/s < v_min = 50
    fast = [(0.0, 0.0), (500.0, 0.0), (1000.0, 0.0), (1500.0, 0.0)]  # 500 > v_max = 400
    for pts in (slow, fast):
        assert len(make_initiator("logic").initiate(window(pts))) == 0
    assert len(LogicInitiator(v_min=10.0).initiate(window(slow))) == 1
    assert len(LogicInitiator(v_max=600.0).initiate(window(fast))) == 1


def test_three_of_four_with_a_missed_scan():
    pts = [(0.0, 0.0), (200.0, 0.0), None, (600.0, 0.0)]
    tr = make_initiator("modified-logic").initiate(window(pts))
    assert len(tr) == 1
    np.testing.assert_array_equal(tr.plots[0], [0, 0, -1, 0])
    np.testing.assert_allclose(tr.x[0, [1, 3]], [200.0, 0.0], atol=1e-9)
    # two plots only: no track
    assert len(make_initiator("logic").initiate(window([(0.0, 0.0), None, None,
                                                        (600.0, 0.0)]))) == 0


def test_branching_on_every_plot_in_the_gate():
    # two candidates at scan 3, both inside the gate and straight enough for plain logic
    pts = [(0.0, 0.0), (200.0, 0.0), [(400.0, 0.0), (400.0, 100.0)], None]
    tr = make_initiator("logic").initiate(window(pts))
    assert len(tr) == 2
    assert sorted(tr.plots[:, 2].tolist()) == [0, 1]


def test_window_size_and_parameters_are_checked():
    with pytest.raises(ValueError, match="window has 3 scans"):
        make_initiator("logic").initiate(window([(0, 0)] * 3))
    with pytest.raises(ValueError, match="v_min"):
        LogicInitiator(v_min=500.0, v_max=400.0).initiate(window([(0, 0)] * 4))
    with pytest.raises(ValueError, match="unknown initiation method"):
        make_initiator("magic")


def test_window_stacks_scans():
    w = Window.from_scans(window([(0.0, 0.0), None, (1.0, 1.0), (2.0, 2.0)], far=False))
    np.testing.assert_array_equal(w.start, [0, 1, 1, 2, 3])
    np.testing.assert_array_equal(w.slot, [0, 2, 3])
    np.testing.assert_allclose(w.R_inv[0], np.eye(2) / 400.0)


def _pairs_by_tree(pts, centres, r):
    """The k-d tree ball query with the widened radius (the former prefilter)."""
    from scipy.spatial import cKDTree

    from mhtrack.initiation.logic import _ball
    return _ball(cKDTree(pts), centres, r * (1.0 + 1e-12) + 1e-9)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(0, 30), m=st.integers(1, 30))
def test_candidate_pairs_equal_the_kd_tree_query_and_hold_every_pair_in_range(seed, n, m):
    """All-pairs prefilter against scipy's ball query (same pairs, same order) and against
    the rule ``‖p − c‖ ≤ r``: every pair within the radius is kept."""
    from mhtrack.initiation import logic
    rng = np.random.default_rng(seed)
    pts = rng.uniform(0, 3000.0, (m, 2))
    centres = rng.uniform(0, 3000.0, (n, 2))
    r = rng.uniform(0, 1500.0, n)
    q, j = logic._candidates(pts, centres, r)
    tq, tj = _pairs_by_tree(pts, centres, r)
    np.testing.assert_array_equal(q, tq)
    np.testing.assert_array_equal(j, tj)
    d = np.hypot(*(pts[None] - centres[:, None]).transpose(2, 0, 1))
    inside = set(zip(*np.nonzero(d <= r[:, None]), strict=True))
    assert inside <= set(zip(q.tolist(), j.tolist(), strict=True))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 20), chi2=st.sampled_from([None, 9.0]))
def test_timed_branching_is_the_same_with_all_pairs_or_the_kd_tree(seed, n, chi2):
    """The timed logic (plots at their own times) finds the same tracks, in the same order,
    whether its gates take candidates from all pairs or from the k-d tree (the former
    code path, forced by a zero pair limit)."""
    from mhtrack.initiation import logic
    from mhtrack.initiation.logic import branch_tracks
    rng = np.random.default_rng(seed)
    scans = []
    for s in range(4):
        t = 4.0 * s + rng.uniform(0, 1.0, n)
        z = np.array([1000.0, 500.0]) + np.array([200.0, -90.0]) * t[:, None] \
            + rng.normal(0, 150.0, (n, 2)) * rng.integers(0, 2, (n, 1)) \
            + rng.uniform(-2000.0, 2000.0, (n, 2)) * rng.integers(0, 2, (n, 1))
        scans.append(Scan(s, 4.0 * s + 1.0, z, np.zeros(n, np.int64), np.arange(n) + n * s,
                          np.broadcast_to(np.diag([90.0**2, 400.0**2]), (n, 2, 2)).copy(),
                          None, t))
    w = Window.from_scans(scans)
    th = np.radians([20.0, 180.0])
    a = branch_tracks(w, th, gate_chi2=chi2)
    old = logic.BRUTE_PAIRS
    try:
        logic.BRUTE_PAIRS = 0
        b = branch_tracks(w, th, gate_chi2=chi2)
    finally:
        logic.BRUTE_PAIRS = old
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)


def test_the_timed_logic_loads_no_scipy():
    """The timed gates take their candidates from all pairs: a timed birth (``mhtrack
    track`` of timed plots with ``--birth logic``) loads no scipy, as every-plot births."""
    import subprocess
    import sys
    code = (
        "import sys, numpy as np\n"
        "from mhtrack.initiation import Window\n"
        "from mhtrack.initiation.logic import branch_tracks\n"
        "from mhtrack.records import Scan\n"
        "sc = [Scan(s, 4.0 * s, np.array([[200.0 * 4 * s, 0.0]]), np.zeros(1, np.int64),\n"
        "           np.array([s]), np.eye(2)[None] * 100.0, None, np.array([4.0 * s]))\n"
        "      for s in range(4)]\n"
        "p, _, _ = branch_tracks(Window.from_scans(sc), np.array([np.pi]))\n"
        "print(len(p), sorted(m for m in sys.modules if m.startswith('scipy')))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    n, modules = out.stdout.split(maxsplit=1)
    assert int(n) >= 1 and modules.strip() == "[]", out.stdout  # the line found, no scipy
