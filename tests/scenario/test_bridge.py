"""Bridging short gaps of recorded trajectories (scenario.trajectory.bridge_gaps)."""

from __future__ import annotations

import numpy as np

from mhtrack.scenario.presets import OPENSKY_MAX_GAP_S, preset
from mhtrack.scenario.trajectory import bridge_gaps


def test_a_constant_velocity_gap_is_filled_exactly_and_a_long_one_kept() -> None:
    v = np.array([120.0, -35.0])
    scans = np.array([0, 1, 4, 5, 30])  # gaps of 3 scans (30 s) and 25 scans (250 s)
    t = scans * 10.0
    states = np.column_stack((1000 + v[0] * t, np.full(5, v[0]), -500 + v[1] * t,
                              np.full(5, v[1])))
    sc, st = bridge_gaps(scans, states, 10.0, 120.0)
    assert sc.tolist() == [0, 1, 2, 3, 4, 5, 30]
    tt = sc * 10.0  # a straight line at constant speed is a cubic: Hermite is exact
    np.testing.assert_allclose(st[:, 0], 1000 + v[0] * tt, atol=1e-9)
    np.testing.assert_allclose(st[:, 2], -500 + v[1] * tt, atol=1e-9)
    np.testing.assert_allclose(st[:, [1, 3]], np.broadcast_to(v, (7, 2)), atol=1e-12)


def test_opensky_radars_keeps_only_long_gaps() -> None:
    for tg in preset("opensky-radars").targets:
        gaps = np.diff(np.asarray(tg.scans)) * 10.0
        assert not ((gaps > 10.0) & (gaps <= OPENSKY_MAX_GAP_S)).any()
