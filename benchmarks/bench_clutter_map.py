"""Clutter-stage time per scan and clutter error of the new estimators (``map``, the
per-radar clutter map; ``fgmm``, the forgetting mixture) beside the GMM's, in one run.

Run: ``python benchmarks/bench_clutter_map.py [--seeds N] [--figure PATH]``.

* scan path, ``crossing-changing`` (one sensor, 90 scans): each estimator fed every scan
  (``update`` + ``intensity`` at the scan's plots: the tracker's clutter stage) — median
  and mean ms per scan, ratio to the GMM's measured in the same run, and the clutter error
  ``IAE = ∫|κ̂ − κ|`` (plots per scan, 100² grid) averaged over scans and seeds;
* timed path, ``opensky-radars`` (rotating radars, frames of one sensor's sector): the
  tracker's per-radar estimator (``PerSensorClutter`` of maps, of GMMs in polar) fed the
  frames in order — ms per frame and ratio; with ``--figure``, each radar's clutter map
  at four times drawn to PATH.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable

import numpy as np

from mhtrack.build import make_clutter_estimator, make_tracker
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.radar_map import map_snapshots
from mhtrack.experiments.pipeline import scenario_source
from mhtrack.metrics.clutter import integrated_absolute_error, true_intensity_grid
from mhtrack.records import Scan
from mhtrack.scenario import preset, simulate

NAMES = ("gmm", "agmm", "fgmm", "map")


def feed(est: ClutterEstimator, scans: list[Scan],
         probe: Callable[[Scan], None] | None = None) -> np.ndarray:
    """Seconds of ``update`` + ``intensity`` per scan (the probe is not timed)."""
    out = []
    for s in scans:
        t0 = time.perf_counter()
        est.update(s, None)
        est.intensity(s.z)
        out.append(time.perf_counter() - t0)
        if probe is not None:
            probe(s)
    return np.array(out)


def scan_path(seeds: int) -> None:
    sc = preset("crossing-changing")
    grid, cell = sc.region.grid(100)
    times: dict[str, list[np.ndarray]] = {n: [] for n in NAMES}
    iae: dict[str, list[float]] = {n: [] for n in NAMES}
    for seed in range(1, seeds + 1):
        sim = simulate(sc, seed=seed)
        scans = list(sim.plots.scans())
        for n in NAMES:
            est = make_clutter_estimator(n)
            errs: list[float] = []

            def probe(s: Scan, est: ClutterEstimator = est, errs: list[float] = errs,
                      sim: object = sim) -> None:
                errs.append(integrated_absolute_error(
                    est.intensity(grid), true_intensity_grid(sim, int(s.index), grid), cell))
            times[n].append(feed(est, scans, probe))
            iae[n].append(float(np.mean(errs)))
    print(f"scan path: crossing-changing, seeds 1..{seeds}, 90 scans each")
    gmm = np.median(np.concatenate(times["gmm"]))
    print("| estimator | median ms/scan | mean ms/scan | × GMM (median) | IAE (plots/scan) |")
    print("|---|---|---|---|---|")
    for n in NAMES:
        t = np.concatenate(times[n])
        print(f"| {n} | {1e3 * np.median(t):.3f} | {1e3 * t.mean():.3f} | "
              f"{np.median(t) / gmm:.2f} | {np.mean(iae[n]):.2f} |")


def timed_path(figure: str | None) -> None:
    sc = preset("opensky-radars")
    sim = simulate(sc, seed=1)
    frames = list(scenario_source(sc, sim.plots))
    sensors = scenario_source(sc, sim.plots).sensors
    t_all = [float(f.time) for f in frames]
    when = np.quantile(t_all, [0.25, 0.5, 0.75, 1.0])
    snaps: list[dict] = []
    print(f"timed path: opensky-radars seed 1, {len(frames)} frames, "
          f"{sum(len(f) for f in frames)} plots")
    print("| estimator | median ms/frame | mean ms/frame | × GMM (mean) |")
    print("|---|---|---|---|")
    res = {}
    for n in ("gmm", "fgmm", "map"):
        clutter = make_tracker(f"mht-{n}", sensors=sensors).clutter
        nxt = [0]

        def probe(s: Scan, clutter: ClutterEstimator = clutter, n: str = n,
                  nxt: list[int] = nxt) -> None:
            if n == "map" and nxt[0] < len(when) and float(s.time) >= when[nxt[0]]:
                snaps.append(map_snapshots(clutter, float(s.time)))
                nxt[0] += 1
        res[n] = feed(clutter, frames, probe)
    for n, t in res.items():
        print(f"| {n} | {1e3 * np.median(t):.3f} | {1e3 * t.mean():.3f} | "
              f"{t.mean() / res['gmm'].mean():.2f} |")
    if figure:
        from mhtrack.plotting.clutter_map import plot_clutter_maps
        from mhtrack.plotting.scene import save_figure

        save_figure(plot_clutter_maps(snaps, title="opensky-radars seed 1: clutter map "
                                      "per radar"), figure, tight=False)
        print(f"wrote {figure}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--figure", default=None)
    ap.add_argument("--skip-timed", action="store_true")
    a = ap.parse_args()
    scan_path(a.seeds)
    if not a.skip_timed:
        timed_path(a.figure)
    return 0


if __name__ == "__main__":
    sys.exit(main())
