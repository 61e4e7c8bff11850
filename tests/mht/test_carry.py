"""The store after a frame with the carried trees left in place (``mhtrack.mht.carry``)
and the coverage's beam test only within a radar's range: the same arrays, bit for
bit, as the former path — the carried leaves copied out, merged with every column and
then pruned; the beam test over every leaf — on random stores and on a tracker run of
a multi-radar scene (frames are sectors) where the caps cut and a radar falls silent."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest
from leaves_fixture import leaves_of_trees

from mhtrack.build import make_tracker
from mhtrack.kernels import mean
from mhtrack.mht import MHTConfig
from mhtrack.mht import timed as timed_module
from mhtrack.mht import tracker as tracker_module
from mhtrack.mht.carry import Carried, merge_carried, number_frame
from mhtrack.mht.coverage import MAX_EDGE_DEG, Looks, RadarCoverage, grid_bearing
from mhtrack.mht.numbering import Counter, number_and_merge
from mhtrack.mht.pruning import take_kept
from mhtrack.mht.tree import STATE, Leaves
from mhtrack.scenario import simulate
from mhtrack.scenario.network import network_scenario


def _same(got, ref) -> None:
    """Every array field equal, bit for bit (NaN equal to NaN), same dtype and shape."""
    for f in dataclasses.fields(ref):
        a, b = getattr(ref, f.name), getattr(got, f.name)
        if isinstance(a, np.ndarray):
            assert b.dtype == a.dtype and b.shape == a.shape, f.name
            assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), f.name


@pytest.mark.parametrize("seed", range(16))
def test_merge_then_take_equals_copy_merge_take(seed):
    rng = np.random.default_rng(seed)
    ids = rng.permutation(40)
    store = leaves_of_trees(rng, int(rng.integers(1, 80)), ids[:30])
    stepped = np.isin(store.tree, ids[:30][rng.random(30) < 0.3])
    carried = Carried(store, (~stepped).nonzero()[0])
    grown = leaves_of_trees(rng, int(rng.integers(0, 30)) * int(seed % 5 != 0),
                            np.unique(store.tree[stepped]) if stepped.any() else ids[30:])
    births = leaves_of_trees(rng, int(rng.integers(0, 6)) * int(seed % 3 != 0),
                             np.arange(40, 50))
    ref = number_and_merge(grown, births, carried.leaves(), Counter(7))
    lazy, merged = merge_carried(grown, births, carried, Counter(7))
    assert merged is not None
    for f in STATE:  # placeholders until pruning
        assert np.isnan(getattr(lazy, f)).all() and not getattr(lazy, f).flags.writeable
    _same(replace(lazy, **{f: getattr(ref, f) for f in STATE}), ref)
    chosen = np.unique(rng.integers(0, max(len(ref), 1), 5)) if len(ref) else np.zeros(0, int)
    for rows in (None, np.flatnonzero(rng.random(len(ref)) < 0.6), np.zeros(0, np.int64)):
        _same(take_kept(lazy, rows, chosen, merged), take_kept(ref, rows, chosen))


def test_grown_out_of_tree_order_take_the_whole_path():
    rng = np.random.default_rng(3)
    store = leaves_of_trees(rng, 20, np.arange(10))
    carried = Carried(store, (store.tree >= 5).nonzero()[0])
    grown = leaves_of_trees(rng, 8, np.arange(5))
    grown = grown.take(np.arange(8)[::-1])
    births = leaves_of_trees(rng, 2, np.arange(10, 12))
    got, parts = number_frame(grown, births, carried, Counter(0))
    assert parts is None
    _same(got, number_and_merge(grown, births, carried.leaves(), Counter(0)))


# ---------------------------------------------------------------- the former paths
def _former_detection(self, scan, x, P, time) -> Looks:
    """``RadarCoverage.detection`` before the beam test was restricted to the leaves
    within range (the reference: every leaf through every formula)."""
    sid = self._sensor_id(scan)
    sensor = self.sensors.sensor(sid)
    pd = min(sensor.pd, self.max_pd)
    tf = float(scan.time)
    t_plots = scan.plot_times()
    t0 = self._last_end.get(sid, float(t_plots.min()) if len(scan) else tf)
    self._last_end[sid] = tf
    site = self._site_of(sid)
    x = np.asarray(x, float).reshape(-1, 4)
    looked = np.ones(len(x), bool)
    if site is None:
        return Looks(np.full(len(x), pd), looked)
    dt = tf - np.asarray(time, float)
    px = x[:, 0] + x[:, 1] * dt - site[0]
    py = x[:, 2] + x[:, 3] * dt - site[1]
    dist = np.hypot(px, py)
    if sensor.max_range is not None:
        looked &= dist <= sensor.max_range
        inside = looked
    elif self.learn_reach:
        inside = self._learned_reach(sid, scan, site, px, py, dist)
    else:
        inside = looked
    if sensor.period is not None and len(scan):
        omega = 360.0 / sensor.period
        span = tf - t0
        if omega * span < 360.0:
            z = np.asarray(scan.z, float).reshape(-1, 2)
            beam = np.radians(grid_bearing(z[:, 0] - site[0], z[:, 1] - site[1])
                              + omega * (tf - t_plots))
            a_f = math.degrees(math.atan2(mean(np.sin(beam)), mean(np.cos(beam))))
            d0 = t0 - tf
            q0 = grid_bearing(px + x[:, 1] * d0, py + x[:, 3] * d0)
            phi_f = (a_f - grid_bearing(px, py)) % 360.0
            phi_0 = (a_f - omega * span - q0) % 360.0
            sig = np.sqrt(np.maximum(P[:, 0, 0], P[:, 2, 2])) / np.maximum(dist, 1.0)
            band = np.minimum(3.0 * np.degrees(sig) + 3.0 * (sensor.sigma_bearing_deg
                                                             or 0.0), MAX_EDGE_DEG)
            crossed = phi_f < phi_0
            certain = crossed & (phi_f >= band) & (phi_0 <= 360.0 - band)
            possible = crossed | (phi_f > 360.0 - band) | (phi_0 < band)
            return Looks(np.where(looked & possible, pd, 0.0), looked & certain & inside)
    return Looks(np.where(looked, pd, 0.0), looked & inside)


def _former_split(leaves, looks):
    """``split_looked`` with the carried leaves copied out (a store of their own)."""
    looked, lk, idle = timed_module.split_looked(leaves, looks)
    return looked, lk, idle.leaves() if isinstance(idle, Carried) else idle


@cache
def _scene():
    """Six radars, 60 s; radar 2 silent from 20 s to 35 s (its next frame's sweep spans
    more than a rotation: every leaf in range is looked at)."""
    sc = network_scenario(n_radars=6, n_aircraft=60, size_m=(400e3, 300e3), duration_s=60,
                          reach_m=(80e3, 120e3), clutter_per_s=4.0, seed=3)
    scans = [s for s in simulate(sc, seed=1).plots.scans()
             if not (int(np.asarray(s.sensor).flat[0]) == 2 and 20.0 <= s.time <= 35.0)]
    return sc, scans


CASES = {
    "defaults": MHTConfig(new_target_density=1e-10),
    "caps": MHTConfig(new_target_density=1e-10, max_cluster_size=3, scale_caps=False,
                      max_trees=150, max_births_per_scan=40, max_leaves=2_000),
}


def _run(cfg: MHTConfig, former: bool, monkeypatch):
    sc, scans = _scene()
    with monkeypatch.context() as m:
        if former:
            m.setattr(RadarCoverage, "detection", _former_detection)
            m.setattr(tracker_module, "split_looked", _former_split)
        trk = make_tracker("mht", cfg, clutter_density=2e-10, sensors=sc.sensor_set())
        spans = []
        det = trk.coverage.detection

        def spy(scan, x, P, time):
            looks = det(scan, x, P, time)
            spans.append(int(np.count_nonzero(looks.pd > 0)))
            return looks

        trk.coverage.detection = spy
        stats: list = []
        out = trk.run(scans, stats)
    return out, stats, trk.leaves, spans


@pytest.mark.parametrize("name", CASES)
def test_tracker_gives_the_former_path_row_for_row(name, monkeypatch):
    cfg = CASES[name]
    ref, s_ref, lv_ref, n_ref = _run(cfg, True, monkeypatch)
    got, s_got, lv_got, n_got = _run(cfg, False, monkeypatch)
    assert len(ref) > 300
    _same(got, ref)
    _same(lv_got, lv_ref)
    assert [replace(s, time_s=0.0) for s in s_got] == [replace(s, time_s=0.0) for s in s_ref]
    assert n_got == n_ref  # the leaves each frame looked at
    stores = np.array([s.n_leaves for s in s_ref])
    assert np.median(np.array(n_ref[20:]) / np.maximum(stores[19:-1], 1)) < 0.5  # carried
    if name == "caps":
        assert {"max_cluster_size", "max_trees"} <= {k for s in s_ref for k in s.caps}


def test_coverage_within_range_equals_every_leaf():
    """Random leaves about each radar, frame after frame (the sweep's state carried), a
    frame after a silence (sweep over a rotation) and leaves all out of range."""
    sc, scans = _scene()
    new, old = RadarCoverage(sc.sensor_set()), RadarCoverage(sc.sensor_set())
    rng = np.random.default_rng(5)
    for k, scan in enumerate(scans[:120]):
        n = 400
        x = np.column_stack((rng.uniform(-250e3, 250e3, n), rng.normal(0, 200, n),
                             rng.uniform(-200e3, 200e3, n), rng.normal(0, 200, n)))
        if k == 50:
            x[:, 0] += 1e7  # nothing in range
        P = np.tile(np.diag([1e4, 25.0, 1e4, 25.0]), (n, 1, 1)) * rng.uniform(0.1, 50, (n, 1, 1))
        t = scan.time - rng.uniform(0, 12, n)
        a, b = new.detection(scan, x, P, t), _former_detection(old, scan, x, P, t)
        assert np.array_equal(a.pd, b.pd) and np.array_equal(a.certain, b.certain)
        assert a.pd.dtype == b.pd.dtype and a.certain.dtype == b.certain.dtype


def test_carried_store_is_not_copied():
    rng = np.random.default_rng(0)
    store = leaves_of_trees(rng, 30, np.arange(10))
    pd = np.where(store.tree < 3, 0.9, 0.0)
    looked, _, idle = timed_module.split_looked(store, Looks(pd, pd > 0))
    assert isinstance(idle, Carried) and idle.store is store
    assert np.array_equal(idle.rows, np.flatnonzero(store.tree >= 3))
    assert isinstance(looked, Leaves) and np.all(looked.tree < 3)
