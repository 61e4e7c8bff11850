"""Caps that scale with the scene (mhtrack.mht.caps): the rule, its bounds, and the
tracker reporting when and how much a cap acted."""

from __future__ import annotations

import dataclasses
import logging
import tracemalloc

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from mhtrack.clutter import KnownClutter
from mhtrack.experiments import track
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.caps import (
    BURST_PLOTS,
    SCALED,
    describe,
    scaled_limits,
    scan_config,
)
from mhtrack.records import PlotTable, Scan

DEFAULT = MHTConfig()


@given(n=st.integers(0, 900), t=st.integers(0, 100))
def test_small_scenes_keep_the_configured_caps(n, t):
    """Up to 900 plots and 100 tracks per scan (every preset) nothing changes."""
    assert scaled_limits(DEFAULT, n, t) == {k: getattr(DEFAULT, k) for k in SCALED}
    assert scan_config(DEFAULT, n, t) is DEFAULT


@given(n=st.integers(0, 10**6), t=st.integers(0, 10**4), dn=st.integers(0, 10**5),
       dt=st.integers(0, 1000))
def test_limits_grow_with_the_scene_and_stop_at_a_burst(n, t, dn, dt):
    a, b = scaled_limits(DEFAULT, n, t), scaled_limits(DEFAULT, n + dn, t + dt)
    assert all(a[k] <= b[k] for k in SCALED)
    assert all(a[k] >= getattr(DEFAULT, k) for k in SCALED)  # configured values: floors
    assert a["max_births_per_scan"] >= min(n, BURST_PLOTS)  # every plot of a scene
    if n >= BURST_PLOTS:  # a burst: the limits of BURST_PLOTS plots
        assert a == scaled_limits(DEFAULT, BURST_PLOTS, t)
    cfg = scan_config(DEFAULT, n, t)  # a valid configuration (leaves > births)
    assert cfg.max_leaves > cfg.max_births_per_scan


def test_hand_worked_limits_and_switch_off():
    # 6 000 plots, 1 000 tracks: 6000 births, 5·6000 + 1000 trees, 16·6000 + 50·1000
    # leaves, 150·6000 + 50·1000 gated pairs
    assert scaled_limits(DEFAULT, 6000, 1000) == {
        "max_births_per_scan": 6000, "max_trees": 31_000, "max_leaves": 146_000,
        "max_gated_pairs": 950_000}
    off = MHTConfig(scale_caps=False)
    assert scaled_limits(off, 10**6, 10**4) == {k: getattr(off, k) for k in SCALED}
    assert describe({"max_trees": 3, "fusion_greedy": 9}, {"max_trees": 5000}) == \
        "fusion_greedy 9, max_trees 3 (limit 5000)"


def test_the_tree_floor_is_per_sensor_of_the_frames():
    # 30 radars, a sector of 70 plots, 4 000 tracks: floor 30·5 000 over 5·70 + 4 000;
    # the other limits are the frame's (one sensor's)
    assert scaled_limits(DEFAULT, 70, 4000, n_sensors=30) == {
        **scaled_limits(DEFAULT, 70, 4000), "max_trees": 150_000}
    assert scaled_limits(DEFAULT, 6000, 1000, n_sensors=3)["max_trees"] == 31_000  # 5n'+t
    assert scaled_limits(DEFAULT, 6000, 1000, n_sensors=7)["max_trees"] == 35_000
    off = MHTConfig(scale_caps=False)  # the configured values, whatever the sensors
    assert scaled_limits(off, 70, 4000, n_sensors=30) == {k: getattr(off, k) for k in SCALED}


def _scene_scans(n_clutter: int, n_scans: int, seed: int) -> list[Scan]:
    """Four targets crossing in uniform clutter over 8 km × 8 km, P_D = 1."""
    rng = np.random.default_rng(seed)
    x0 = np.array([[-3000.0, 0.0], [3000.0, 0.0], [0.0, -3000.0], [0.0, 3000.0]])
    v = -x0 / 60.0
    scans = []
    for k in range(1, n_scans + 1):
        tz = x0 + v * k + rng.normal(0, 100, x0.shape)
        z = np.vstack((tz, rng.uniform(-4000, 4000, (n_clutter, 2))))
        origin = np.r_[np.arange(1, 5), np.full(n_clutter, -1)]
        s = Scan.from_positions(k, float(k), z)
        scans.append(dataclasses.replace(s, origin=origin))
    return scans


def test_a_scene_larger_than_the_floors_is_not_capped():
    """3 000 plots per scan: the fixed caps cut births (2 000), the scaled ones do not."""
    scans = _scene_scans(3000, 3, 1)
    kappa = 3000 / 8000.0**2
    fixed = MHTTracker(MHTConfig(scale_caps=False), KnownClutter(kappa))
    run_fixed = track(fixed, PlotTable.from_scans(scans))
    assert "max_births_per_scan" in run_fixed.caps
    scaled = MHTTracker(MHTConfig(), KnownClutter(kappa))
    run = track(scaled, PlotTable.from_scans(scans))
    assert "max_births_per_scan" not in run.caps
    assert run.stats[0].n_births == 3004  # every plot started a tree
    assert run.stats[0].limits["max_births_per_scan"] == 3004


def test_a_burst_is_bounded_and_says_what_it_capped(caplog):
    """A scan of BURST_PLOTS + 5 000 plots after normal ones: births cut to the burst
    limit, leaves within theirs, memory bounded, one warning naming the scan, its plots,
    the cap and its limit; the run lists the scans where each cap acted."""
    scans = _scene_scans(40, 4, 2)
    n = BURST_PLOTS + 5000
    rng = np.random.default_rng(3)
    burst = Scan.from_positions(5, 5.0, rng.uniform(-4000, 4000, (n, 2)))
    scans.append(dataclasses.replace(burst, origin=np.full(n, -1)))
    trk = MHTTracker(MHTConfig(), KnownClutter(40 / 8000.0**2))
    tracemalloc.start()
    try:
        with caplog.at_level(logging.WARNING, logger="mhtrack.mht.tracker"):
            run = track(trk, PlotTable.from_scans(scans))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    st5 = run.stats[-1]
    assert st5.n_plots == n
    assert st5.limits["max_births_per_scan"] == BURST_PLOTS
    assert st5.caps["max_births_per_scan"] == n - BURST_PLOTS
    assert st5.n_births == BURST_PLOTS
    assert st5.n_leaves <= st5.limits["max_leaves"] and st5.n_trees <= st5.limits["max_trees"]
    assert run.cap_scans["max_births_per_scan"] == [5]
    lines = [r.getMessage() for r in caplog.records if "caps" in r.getMessage()]
    assert len(lines) == 1
    assert f"MHT scan 5 ({n} plots)" in lines[0]
    assert f"max_births_per_scan {n - BURST_PLOTS} (limit {BURST_PLOTS})" in lines[0]
    assert peak < 1.5 * 2**30


def test_a_replaced_config_gives_its_own_limits():
    """A tracker whose ``config`` is replaced scales the new configuration's caps."""
    trk = MHTTracker(MHTConfig(), KnownClutter(1e-8))
    z = np.array([[0.0, 0.0], [500.0, 500.0]])
    trk.step(Scan.from_positions(0, 0.0, z))
    assert trk.last_stats.limits == {k: getattr(scan_config(MHTConfig(), 2, 0), k)
                                     for k in SCALED}
    trk.config = MHTConfig(max_trees=7, scale_caps=False)
    trk.step(Scan.from_positions(1, 1.0, z))
    assert trk.last_stats.limits["max_trees"] == 7


def test_the_tree_floor_counts_only_rotating_sensors():
    """Only sensors with a rotation period give sector frames; one without a period (or
    none at all) looks at everything each frame and counts as the single scan's one."""
    from mhtrack.mht.coverage import RadarCoverage
    from mhtrack.models.radars import RadarSensor, SensorSet

    def radar(i: int, period: float | None) -> RadarSensor:
        return RadarSensor(i, "polar", lat=51.0 + 0.1 * i, lon=0.0, sigma_range=50.0,
                           sigma_bearing_deg=0.1, pd=0.9, period=period)

    mixed = SensorSet(None, (radar(1, 4.0), radar(2, None), radar(3, 6.0), radar(4, None)))
    assert RadarCoverage(mixed).n_sensors == 2
    still = SensorSet(None, (radar(1, None), radar(2, None)))
    assert RadarCoverage(still).n_sensors == 1
    assert scaled_limits(DEFAULT, 70, 400, n_sensors=RadarCoverage(mixed).n_sensors)[
        "max_trees"] == 2 * DEFAULT.max_trees


@pytest.mark.parametrize("n_plots,n_tracks,n_sensors", [(0, 0, 1), (7, 3, 1), (400, 2_000, 30),
                                                        (10**6, 10**5, 4)])
def test_scan_config_equals_replace(n_plots, n_tracks, n_sensors):
    """The per-frame copy without the configuration's checks equals
    ``dataclasses.replace`` (which runs them) field for field."""
    from mhtrack.mht.caps import scaled_limits, scan_config

    for cfg in (MHTConfig(), MHTConfig(max_trees=3, max_leaves=50, max_births_per_scan=2)):
        got = scan_config(cfg, n_plots, n_tracks, n_sensors)
        lim = scaled_limits(cfg, n_plots, n_tracks, n_sensors)
        assert got == dataclasses.replace(cfg, **lim)
        assert {k: getattr(got, k) for k in lim} == lim


def test_scan_config_still_refuses_a_floor_out_of_range():
    from mhtrack.bounds import MAX_INDEX
    from mhtrack.mht.caps import scan_config

    cfg = MHTConfig(max_trees=MAX_INDEX // 2, max_leaves=MAX_INDEX)
    with pytest.raises(ValueError, match="max_trees"):
        scan_config(cfg, 5, 0, 30)  # 30 sensors × the floor: beyond MAX_INDEX
