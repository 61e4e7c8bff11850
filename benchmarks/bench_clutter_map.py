"""Clutter-stage time per scan and clutter error of the new estimators (``map``, the
per-radar clutter map; ``fgmm``, the forgetting mixture; ``mapgmm``, the GMM calibrated by
a map) beside the GMM's, in one run.

Run: ``python benchmarks/bench_clutter_map.py [--seeds N] [--figure PATH] [--clock cpu]``
(``--clock cpu``: the thread's CPU time, ``time.thread_time``, instead of the wall clock —
on a shared, loaded machine the wall clock also counts the time other processes ran;
``--path``: the scan path with the cell-mass quadrature's NumPy path, its compiled loops
(:mod:`mhtrack.clutter.cell_mass_rows`, numba), or both, one after the other; the same
floats either way, so the same IAE).

* scan path, ``crossing-changing`` (one sensor, 90 scans): each estimator fed every scan
  (``update`` + ``intensity`` at the scan's plots: the tracker's clutter stage), the
  estimators taking turns scan by scan — median and mean ms per scan, ratios to the GMM's
  (of the medians, the median of the per-scan ratios, of the means), and the clutter error
  ``IAE = ∫|κ̂ − κ|`` (plots per scan, 100² grid) averaged over scans and seeds;
* timed path, ``opensky-radars`` and ``radars-clutter`` with the ``storm`` clutter scene
  (rotating radars, frames of one sensor's sector): the tracker's per-radar estimator
  (``PerSensorClutter`` of maps, of GMMs in polar) fed the frames in order — ms per frame
  and ratio; with ``--figure``, each radar's clutter map on ``opensky-radars`` at four
  times drawn to PATH.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable

import numpy as np

from mhtrack.build import make_clutter_estimator, make_tracker
from mhtrack.clutter import cell_mass, cell_mass_rows
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.radar_map import map_snapshots
from mhtrack.experiments.pipeline import scenario_source
from mhtrack.metrics.clutter import integrated_absolute_error, true_intensity_grid
from mhtrack.records import Scan
from mhtrack.scenario import preset, simulate

NAMES = ("gmm", "agmm", "fgmm", "map", "mapgmm")


CLOCK: list[Callable[[], float]] = [time.perf_counter]


def interleaved(ests: dict[str, ClutterEstimator], scans: list[Scan],
                probe: Callable[[str, ClutterEstimator, Scan], None] | None = None
                ) -> dict[str, np.ndarray]:
    """Seconds of ``update`` + ``intensity`` per scan of each estimator, the estimators
    taking turns scan by scan (so that a shared machine's load falls on all alike)."""
    out: dict[str, list[float]] = {n: [] for n in ests}
    for s in scans:
        for n, est in ests.items():
            clock = CLOCK[0]
            t0 = clock()
            est.update(s, None)
            est.intensity(s.z)
            out[n].append(clock() - t0)
            if probe is not None:
                probe(n, est, s)
    return {n: np.array(v) for n, v in out.items()}


def _table(times: dict[str, list[np.ndarray]], unit: str,
           iae: dict[str, list[float]] | None = None) -> None:
    ref = np.concatenate(times["gmm"])
    print(f"| estimator | median ms/{unit} | mean ms/{unit} | × GMM (medians) | "
          f"median of per-{unit} ratios | × GMM (means) |" + (" IAE (plots/scan) |" if iae
                                                            else ""))
    print("|---|---|---|---|---|---|" + ("---|" if iae else ""))
    for n, ts in times.items():
        t = np.concatenate(ts)
        ratio = np.median(t / np.maximum(ref, 1e-9))
        row = (f"| {n} | {1e3 * np.median(t):.3f} | {1e3 * t.mean():.3f} | "
               f"{np.median(t) / np.median(ref):.2f} | {ratio:.2f} | {t.mean() / ref.mean():.2f} |")
        print(row + (f" {np.mean(iae[n]):.2f} |" if iae else ""))


def scan_path(seeds: int) -> None:
    sc = preset("crossing-changing")
    grid, cell = sc.region.grid(100)
    times: dict[str, list[np.ndarray]] = {n: [] for n in NAMES}
    iae: dict[str, list[float]] = {n: [] for n in NAMES}
    for seed in range(1, seeds + 1):
        sim = simulate(sc, seed=seed)
        errs: dict[str, list[float]] = {n: [] for n in NAMES}

        def probe(n: str, est: ClutterEstimator, s: Scan, sim: object = sim,
                  errs: dict[str, list[float]] = errs) -> None:
            errs[n].append(integrated_absolute_error(
                est.intensity(grid), true_intensity_grid(sim, int(s.index), grid), cell))
        res = interleaved({n: make_clutter_estimator(n) for n in NAMES},
                          list(sim.plots.scans()), probe)
        for n in NAMES:
            times[n].append(res[n])
            iae[n].append(float(np.mean(errs[n])))
    print(f"scan path: crossing-changing, seeds 1..{seeds}, 90 scans each")
    _table(times, "scan", iae)


def timed_path(figure: str | None, scene: str | None = None) -> None:
    from mhtrack.scenario.scenes import with_clutter_scene

    sc = (preset("opensky-radars") if scene is None
          else with_clutter_scene(preset("radars-clutter", scans=150), scene))
    sim = simulate(sc, seed=1)
    frames = list(scenario_source(sc, sim.plots))
    sensors = scenario_source(sc, sim.plots).sensors
    t_all = [float(f.time) for f in frames]
    when = np.quantile(t_all, [0.25, 0.5, 0.75, 1.0])
    snaps: list[dict] = []
    print(f"timed path: {sc.name} seed 1, {len(frames)} frames, "
          f"{sum(len(f) for f in frames)} plots")
    clutters = {n: make_tracker(f"mht-{n}", sensors=sensors).clutter
                for n in ("gmm", "fgmm", "map", "mapgmm")}
    nxt = [0]

    def probe(n: str, clutter: ClutterEstimator, s: Scan) -> None:
        if n == "map" and nxt[0] < len(when) and float(s.time) >= when[nxt[0]]:
            snaps.append(map_snapshots(clutter, float(s.time)))
            nxt[0] += 1
    res = interleaved(clutters, frames, probe)
    _table({n: [t] for n, t in res.items()}, "frame")
    if figure and scene is None:
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
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall")
    ap.add_argument("--path", choices=("both", "numpy", "compiled"), default="both",
                    help="the cell-mass quadrature's NumPy path, its compiled loops "
                    "(numba, extra [fast]), or one after the other (default)")
    a = ap.parse_args()
    CLOCK[0] = time.thread_time if a.clock == "cpu" else time.perf_counter
    print(f"clock: {a.clock}")
    for path in (("numpy", "compiled") if a.path == "both" else (a.path,)):
        on = cell_mass_rows.use(path == "compiled") and cell_mass.preload()
        if path == "compiled" and not on:
            print("compiled loops: numba not installed (or MHTRACK_COMPILED=0)")
            continue
        print(f"cell-mass quadrature: {path} path")
        scan_path(a.seeds)
        if not a.skip_timed:
            timed_path(a.figure)
            timed_path(None, "storm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
