"""The network scene (``mhtrack.scenario.network``) and the simulator's reach pre-filter
(``sweep.may_reach``)."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.models.geodesy import LocalFrame, local_to_polar
from mhtrack.scenario import simulate, sweep
from mhtrack.scenario.network import CRUISE_SPEED, TERMINAL_SPEED, network_scenario


def small(**kw):
    args = dict(n_radars=6, n_aircraft=40, size_m=(400e3, 300e3), duration_s=30,
                reach_m=(80e3, 120e3), clutter_per_s=2.0, seed=3)
    args.update(kw)
    return network_scenario(**args)


def test_scene_follows_its_rules():
    sc = small()
    assert sc == small()  # one seed, one scene
    assert sc != small(seed=4)
    frame = LocalFrame(*sc.origin)
    x, y = frame.to_local([s.lat for s in sc.sensors], [s.lon for s in sc.sensors])
    # a 3 x 2 grid of 133 x 150 km cells: one site per cell, in its middle half
    cx = np.floor((np.asarray(x) + 200e3) / (400e3 / 3))
    cy = np.floor((np.asarray(y) + 150e3) / 150e3)
    assert len(set(zip(cx.tolist(), cy.tolist(), strict=True))) == 6
    fx = (np.asarray(x) + 200e3) / (400e3 / 3) - cx
    assert ((fx >= 0.25 - 1e-6) & (fx <= 0.75 + 1e-6)).all()
    for s in sc.sensors:
        assert 4.0 <= s.period <= 12.0 and round(s.period, 1) == s.period
        assert 80e3 <= s.max_range <= 120e3
        assert s.clutter_rate == pytest.approx(2.0 * s.period)
    st = np.array([t.state for t in sc.targets])
    speed = np.hypot(st[:, 1], st[:, 3])
    cruise = (speed >= CRUISE_SPEED[0]) & (speed <= CRUISE_SPEED[1])
    terminal = (speed >= TERMINAL_SPEED[0]) & (speed <= TERMINAL_SPEED[1])
    assert (cruise | terminal).all() and cruise.sum() > terminal.sum()
    assert (np.abs(st[:, 0]) <= 200e3).all() and (np.abs(st[:, 2]) <= 150e3).all()


def test_target_plots_within_reach_and_prefilter_changes_nothing(monkeypatch):
    sc = small()
    skipped = []
    real = sweep.may_reach
    monkeypatch.setattr(sweep, "may_reach", lambda *a: real(*a) or skipped.append(1))
    sim = simulate(sc, seed=1)
    assert len(skipped) > 40  # the pre-filter acted (6 radars x 40 aircraft pairs)
    p = sim.plots
    assert len(p) > 0 and (p.origin >= 0).any()
    radars = {s.id: s for s in sc.sensors}
    frame = LocalFrame(*sc.origin)
    truth_t = {int(s.id) for s in sc.targets}
    for sid, r in radars.items():
        rows = (p.sensor == sid) & (p.origin >= 0)
        assert set(p.origin[rows].tolist()) <= truth_t
        # every target plot's true position is within the radar's reach; measured range too,
        # give or take 5 sigma of noise
        assert (p.range[rows] <= r.max_range + 5 * r.sigma_range).all()
        rng, _ = local_to_polar(frame, r.lat, r.lon, p.x[rows], p.y[rows])
        assert (np.asarray(rng) <= r.max_range * 1.01 + 1e3).all()
    # the former path (no pre-filter) gives the same plots, bit for bit
    monkeypatch.setattr(sweep, "may_reach", lambda *a: True)
    ref = simulate(sc, seed=1).plots
    for k in ("time", "sensor", "x", "y", "range", "bearing", "origin", "scan"):
        np.testing.assert_array_equal(getattr(p, k), getattr(ref, k))
