"""Two regions, one tracker each, and the hand-over of ``mhtrack.pipeline.regions``:
aircraft that cross the border keep one system id (checked by the plots' true origins,
not by the hand-over's own bookkeeping)."""

from __future__ import annotations

import numpy as np

from mhtrack.build.radar_defaults import radar_rule
from mhtrack.mht import MHTConfig
from mhtrack.models.clutter import Region, UniformClutter
from mhtrack.models.geodesy import LocalFrame
from mhtrack.models.sensors import RotatingRadar
from mhtrack.pipeline.regions import HandOver, Partition, RegionTracker
from mhtrack.records import Scan, TrackTable
from mhtrack.scenario import Scenario, Target, simulate

ORIGIN = (50.0, 5.0)
BOX = Region(-200e3, 200e3, -200e3, 200e3)


def crossing_scene() -> Scenario:
    """Two radars 50 km either side of the border x = 0; six aircraft crossing it (four
    eastbound, two westbound, 15 km apart in y) around t = 130 s."""
    lat, lon = LocalFrame(*ORIGIN).to_geodetic([-50e3, 50e3], [0.0, 0.0])
    radars = tuple(RotatingRadar(id=i + 1, lat=float(lat[i]), lon=float(lon[i]), period=p,
                                 phase=40.0 * i, sigma_range=40.0, sigma_bearing_deg=0.08,
                                 max_range=120e3, clutter_rate=5.0)
                   for i, p in enumerate((4.0, 5.0)))
    targets = []
    for k in range(6):
        east = k < 4
        v = 230.0 if east else -230.0
        targets.append(Target(k + 1, (-v * 130.0, v, -40e3 + 15e3 * k, 0.0), 0, 260))
    return Scenario(name="two-regions", region=BOX, T=1.0, scans=(0, 260),
                    targets=tuple(targets), sensors=radars, pd=0.95,
                    clutter=UniformClutter(BOX, 0.0), origin=ORIGIN)


def run_regions(sim, partition: Partition, batch: int = 8
                ) -> tuple[TrackTable, list[TrackTable], HandOver]:
    """Each region's tracker on its part of every frame; the hand-over every ``batch``
    frames. Returns the published system tracks, each region's own reports, the
    coordinator."""
    p = sim.plots
    rule = radar_rule(sim.scenario.sensor_set(), p.sensor, p.time, p.x, p.y,
                      v_max=MHTConfig().v_max)
    cfg = MHTConfig(new_target_density=rule.new_target_density)
    regions = [RegionTracker("mht-agmm", cfg, sim.scenario.sensor_set())
               for _ in partition.cores]
    hand = HandOver(partition)
    own: list[list[TrackTable]] = [[] for _ in regions]
    published = []
    frames: list[list[Scan]] = [[] for _ in regions]

    def flush() -> None:
        reports = [r.step(f) for r, f in zip(regions, frames, strict=True)]
        for i, r in enumerate(reports):
            own[i].append(r)
            frames[i].clear()
        published.append(hand.assign(reports)[0])

    for n, scan in enumerate(p.scans(), 1):
        for i, part in enumerate(partition.split(scan)):
            frames[i].append(part)
        if n % batch == 0:
            flush()
    flush()
    return TrackTable.concat(published), [TrackTable.concat(o) for o in own], hand


def test_crossing_aircraft_keep_one_system_id():
    sim = simulate(crossing_scene(), seed=1)
    origin = sim.plots.origin
    part = Partition.split_x(BOX, 0.0, 20e3)
    system, own, hand = run_regions(sim, part)
    updated = system.plot >= 0
    who = np.where(updated, origin[np.maximum(system.plot, 0)], -1)
    assert hand.handovers >= 6
    for k in range(1, 7):
        mine = who == k
        # the aircraft is published on both sides of the border, under one system id
        assert (system.x[mine] < -10e3).any() and (system.x[mine] > 10e3).any(), k
        assert np.unique(system.track_id[mine]).size == 1, (k, np.unique(system.track_id[mine]))
        # and once per frame: never by both regions at the same frame
        frames = system.scan[mine]
        assert np.unique(frames).size == frames.size, k
        # each region tracked it under its own id: without the hand-over, two ids
        local = {(i, int(t)) for i, o in enumerate(own)
                 for t in o.track_id[(o.plot >= 0) & (origin[np.maximum(o.plot, 0)] == k)]}
        assert {i for i, _ in local} == {0, 1}, (k, local)


def test_split_keeps_rows_and_overlap():
    sim = simulate(crossing_scene(), seed=2)
    part = Partition.split_x(BOX, 0.0, 20e3)
    for scan in list(sim.plots.scans())[:50]:
        a, b = part.split(scan)
        x = scan.z[:, 0]
        np.testing.assert_array_equal(a.rows, scan.rows[x < 20e3])
        np.testing.assert_array_equal(b.rows, scan.rows[x >= -20e3])
        assert (a.index, a.time, b.index, b.time) == (scan.index, scan.time) * 2
    # the cores are disjoint and cover the box
    x = np.linspace(-199e3, 199e3, 101)
    both = part.in_core(0, x, 0 * x).astype(int) + part.in_core(1, x, 0 * x).astype(int)
    assert (both == 1).all()
