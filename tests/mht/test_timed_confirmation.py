"""Confirmation of trees of asynchronous plots waits for the plot that tests the motion.

One radar (period 4 s, ``P_D`` 0.9) sees a target 20 km north moving east at 100 m/s.
Each rotation has two frames: the target's plot (exact) at the beam's crossing, and half
a rotation later one far plot on the opposite side (it only gives the frame a beam
azimuth). The tree starts from the first plot with velocity ``0 ± v_max/2``, so the
second plot's likelihood only says the two plots are within reach; the third plot is
the first that tests constant velocity (``build.TIMED_CONFIRM_MIN_PLOTS``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from async_fixture import Radar, polar_plot, sensor_set

from mhtrack.build import TIMED_CONFIRM_MIN_PLOTS, make_tracker
from mhtrack.mht import MHTConfig
from mhtrack.records import Scan

RADAR = Radar(1, 0.0, 0.0, period=4.0, phase_deg=0.0, pd=0.9, max_range=100_000.0)
CFG = MHTConfig(new_target_density=1e-10, imm_sigma_v=0.0)


def _frame(index: int, t: float, xy: tuple[float, float]) -> Scan:
    r, b = np.hypot(*xy), np.degrees(np.arctan2(xy[0], xy[1])) % 360.0
    z, R = polar_plot(RADAR, np.array([r]), np.array([b]))
    return Scan(index, t, z, np.array([1]), np.array([index]), R, None, np.array([t]))


def _run(trk, n_rotations: int) -> list[tuple[float, int, int]]:
    """Per target frame: (score, plots on the branch, track id) of the best leaf of the
    target's tree (the tree holding plot row 0)."""
    out = []
    for k in range(n_rotations):
        t = 4.0 * k
        trk.step(_frame(2 * k, t, (100.0 * t, 20_000.0)))
        lv = trk.leaves
        mine = np.flatnonzero(lv.tree == lv.tree[(lv.window == 0).any(1)][0])
        j = int(mine[lv.score[mine].argmax()])
        out.append((float(lv.score[j]), int(lv.n_updates[j]), int(lv.track[j])))
        trk.step(_frame(2 * k + 1, t + 2.0, (-60_000.0, -60_000.0 - 10_000.0 * k)))
    return out


def test_two_plot_tree_above_the_sprt_threshold_waits_for_its_third_plot():
    trk = make_tracker("mht", CFG, clutter_density=1e-10, sensors=sensor_set([RADAR]))
    assert trk.config.confirm_min_plots == TIMED_CONFIRM_MIN_PLOTS == 3
    (s1, n1, id1), (s2, n2, id2), (s3, n3, id3) = _run(trk, 3)
    assert (n1, n2, n3) == (1, 2, 3)
    assert s1 == pytest.approx(math.log(1e-10 * 0.9 / (1e-10 + 1e-10)))  # ln(λ P_D/(κ + λ))
    # Wald's SPRT alone would confirm the two-plot branch: L ≥ ln((1 − β)/α) ...
    assert s2 >= trk.sprt.confirm_threshold
    # ... but two plots have not tested the motion: tentative until the third.
    assert id1 == id2 == -1
    assert id3 >= 0 and s3 > s2


def test_scans_keep_two_plots_and_a_larger_configured_minimum_is_kept():
    assert make_tracker("mht", CFG, clutter_density=1e-10).config.confirm_min_plots == 2
    cfg = MHTConfig(new_target_density=1e-10, imm_sigma_v=0.0, confirm_min_plots=4)
    trk = make_tracker("mht", cfg, clutter_density=1e-10, sensors=sensor_set([RADAR]))
    assert trk.config.confirm_min_plots == 4
    assert [i for _, _, i in _run(trk, 4)][:3] == [-1, -1, -1]
