"""Two regions on two Dask workers with a hand-over at the border (issue 30, item 7;
``docs/scaling.md``), beside one tracker over the whole scene.

    python benchmarks/regions.py [--radars 10] [--aircraft 500] [--duration 300]
        [--overlap-km 40] [--batch-s 4] [--seed 1]

A network scene (:func:`mhtrack.scenario.network.network_scenario`, 800 × 500 km) is
simulated once. Then:

* **one tracker** (``mht-agmm``, the sensors' coverage, ``track``'s radar rule for the
  new-target density) over every frame — the reference;
* **two regions**, west and east of ``x = 0``, each given its plots within ``--overlap-km``
  of its core (:class:`mhtrack.pipeline.regions.Partition`), each tracker a **Dask actor**
  (:class:`~mhtrack.pipeline.regions.RegionTracker` on a ``LocalCluster`` of two worker
  processes, one thread each): the driver sends each region its part of every
  ``--batch-s`` seconds of frames (the role of a Kafka topic per region), gathers both
  regions' reports and gives them system ids (:class:`~mhtrack.pipeline.regions.HandOver`).

Scored by the plots' true origins, for every aircraft whose truth crosses ``x = 0``:
it **keeps its id** when the tracks that used its plots within 120 s of the crossing,
on both sides, carry one id — the system id (two regions), the track id (one tracker), or
the region's own id (two regions without hand-over: ids ``(region, track)``). Also OSPA
(c = 2 km, p = 2, at the truth's times) and wall times.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from mhtrack.build.radar_defaults import radar_rule
from mhtrack.metrics import evaluate
from mhtrack.mht import MHTConfig
from mhtrack.models.clutter import Region
from mhtrack.pipeline.regions import HandOver, Partition, RegionTracker
from mhtrack.records import TrackTable
from mhtrack.scenario import simulate
from mhtrack.scenario.network import network_scenario

WINDOW_S = 120.0


def crossings(truth) -> dict[int, float]:
    """Aircraft id → time its truth first crosses ``x = 0``."""
    out = {}
    order = np.lexsort((truth.time, truth.target_id))
    tid, t, x = truth.target_id[order], truth.time[order], truth.x[order]
    flip = (np.diff(np.sign(x)) != 0) & (tid[1:] == tid[:-1])
    for j in np.flatnonzero(flip):
        out.setdefault(int(tid[j]), float(t[j + 1]))
    return out


def kept(ids: np.ndarray, who: np.ndarray, t: np.ndarray, x: np.ndarray,
         cross: dict[int, float]) -> tuple[int, int]:
    """``(aircraft seen on both sides within WINDOW_S of their crossing, of them those
    under one id there)``; ``ids`` one hashable id per row, ``who`` its plot's origin."""
    seen = one = 0
    for k, tc in cross.items():
        m = (who == k) & (np.abs(t - tc) <= WINDOW_S)
        if not ((x[m] < 0).any() and (x[m] >= 0).any()):
            continue
        seen += 1
        one += np.unique(ids[m]).size == 1
    return seen, one


def origin_of(tracks: TrackTable, origin: np.ndarray) -> np.ndarray:
    return np.where(tracks.plot >= 0, origin[np.maximum(tracks.plot, 0)], -1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--radars", type=int, default=10)
    ap.add_argument("--aircraft", type=int, default=500)
    ap.add_argument("--duration", type=int, default=300)
    ap.add_argument("--overlap-km", type=float, default=40.0)
    ap.add_argument("--batch-s", type=float, default=4.0)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    from distributed import Client, LocalCluster

    t0 = time.perf_counter()
    sc = network_scenario(n_radars=a.radars, n_aircraft=a.aircraft, size_m=(800e3, 500e3),
                          duration_s=a.duration, seed=a.seed)
    sim = simulate(sc, seed=a.seed)
    p, sensors = sim.plots, sc.sensor_set()
    rule = radar_rule(sensors, p.sensor, p.time, p.x, p.y, v_max=MHTConfig().v_max)
    cfg = MHTConfig(new_target_density=rule.new_target_density)
    scans = list(p.scans())
    cross = crossings(sim.truth)
    print(f"scene: {a.radars} radars, {a.aircraft} aircraft, {a.duration} s: {len(p)} plots, "
          f"{len(scans)} frames, {len(cross)} aircraft cross x = 0 "
          f"(simulated in {time.perf_counter() - t0:.0f} s)", flush=True)

    t0 = time.perf_counter()
    one = RegionTracker("mht-agmm", cfg, sensors).step(scans)
    t_one = time.perf_counter() - t0

    part = Partition.split_x(Region(-1e7, 1e7, -1e7, 1e7), 0.0, 1e3 * a.overlap_km)
    hand = HandOver(part)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        actors = [client.submit(RegionTracker, "mht-agmm", cfg, sensors, actor=True,
                                workers=[w]).result()
                  for w in list(client.scheduler_info()["workers"])[:2]]
        t0 = time.perf_counter()
        published, own = [], [[], []]
        times = np.array([s.time for s in scans])
        edges = np.arange(times.min(), times.max() + a.batch_s, a.batch_s)
        starts = np.searchsorted(times, edges)
        for lo, hi in zip(starts[:-1].tolist(), starts[1:].tolist(), strict=True):
            if hi <= lo:
                continue
            split = [part.split(s) for s in scans[lo:hi]]
            futs = [actor.step([s[i] for s in split]) for i, actor in enumerate(actors)]
            reports = [f.result() for f in futs]
            for i, r in enumerate(reports):
                own[i].append(r)
            published.append(hand.assign(reports)[0])
        t_two = time.perf_counter() - t0
    system = TrackTable.concat(published)
    own_t = [TrackTable.concat(o) for o in own]

    def score(tt: TrackTable) -> tuple[float, float, int]:
        e = evaluate(tt, sim.truth, cutoff=2000.0, order=2.0, at="truth-times")
        return e.ospa_mean, e.coverage, e.n_track_ids

    print(f"\nhand-over: {len(hand.systems)} system ids, {hand.handovers} ownership moves; "
          f"overlap {a.overlap_km:g} km, batches of {a.batch_s:g} s")
    print("| run | aircraft crossing, seen both sides | kept one id | OSPA (m) | coverage "
          "| ids | wall (s) |")
    print("|---|---|---|---|---|---|---|")
    o_one = origin_of(one, p.origin)
    s1 = kept(one.track_id, o_one, one.time, one.x, cross)
    q1 = score(one)
    print(f"| one tracker | {s1[0]} | {s1[1]} | {q1[0]:.1f} | {q1[1]:.4f} | {q1[2]} | "
          f"{t_one:.1f} |")
    o_sys = origin_of(system, p.origin)
    s2 = kept(system.track_id, o_sys, system.time, system.x, cross)
    q2 = score(system)
    print(f"| two regions (Dask), system ids | {s2[0]} | {s2[1]} | {q2[0]:.1f} | {q2[1]:.4f} "
          f"| {q2[2]} | {t_two:.1f} |")
    both = TrackTable.concat(own_t)
    region = np.repeat([0, 1], [len(o) for o in own_t])
    naive = both.track_id * 2 + region  # (region, track) as one number
    # each region's own picture, owned rows only would need the hand-over: all rows here
    s3 = kept(naive, origin_of(both, p.origin), both.time, both.x, cross)
    print(f"| two regions, their own ids (no hand-over) | {s3[0]} | {s3[1]} | | | | |")


if __name__ == "__main__":
    main()
