"""Speed of the MHT: seconds per scan on ``crossing``, against Stone Soup's JPDA on the same
plots (both OSPAs and the time ratio), and scaling with targets and clutter.

Run: ``python benchmarks/bench_mht.py [--quick]``. Prints every figure as a ratio against a
reference measured in the same run: Stone Soup's time per scan on the same plots, and for
the scaling table the 10-target, 10-clutter case.
"""

from __future__ import annotations

import argparse
import dataclasses
import resource
import sys
import time

import numpy as np

from mhtrack.clutter import KnownClutter
from mhtrack.experiments import track
from mhtrack.metrics import evaluate
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.models.clutter import Region, UniformClutter
from mhtrack.scenario import Scenario, Target, preset, simulate


def crossing_vs_stonesoup(seed: int, clutter_rate: float) -> None:
    sc = preset("crossing", clutter="uniform", clutter_rate=clutter_rate)
    sim = simulate(sc, seed=seed)
    kappa = clutter_rate / sc.region.area
    cfg = MHTConfig()
    run = track(MHTTracker(cfg, KnownClutter(kappa)), sim.plots)
    ours = run.seconds_per_scan
    ev = evaluate(run.tracks, sim.truth, plots=sim.plots)
    print(f"crossing, uniform clutter {clutter_rate:g}/scan, seed {seed}, kappa={kappa:.4g}")
    print(f"  mhtrack MHT : median {1e3 * np.median(ours):7.2f} ms/scan, "
          f"mean {1e3 * ours.mean():7.2f}, OSPA mean {ev.ospa_mean:6.1f} m")
    try:
        from stonesoup_reference import run_stonesoup_jpda
    except ImportError:  # pragma: no cover
        print("  Stone Soup not installed (pip install -e '.[reference]'): no reference")
        return
    ss_tracks, ss = run_stonesoup_jpda(sim.plots, sigma_w=cfg.sigma_w, sigma_v=cfg.sigma_v,
                                       p_detection=cfg.p_detection, clutter_density=kappa)
    ev_ss = evaluate(ss_tracks, sim.truth, plots=sim.plots)
    print(f"  Stone Soup JPDA: median {1e3 * np.median(ss):7.2f} ms/scan, "
          f"mean {1e3 * ss.mean():7.2f}, OSPA mean {ev_ss.ospa_mean:6.1f} m")
    print(f"  ratio Stone Soup / mhtrack (median time per scan): "
          f"{np.median(ss) / np.median(ours):.1f}x")


def crossing_default(seed: int) -> None:
    sc = preset("crossing")
    sim = simulate(sc, seed=seed)
    run = track(MHTTracker(MHTConfig(), KnownClutter(1e-9)), sim.plots)
    t = run.seconds_per_scan
    print(f"crossing preset (GMM clutter 40/scan), plain MHT kappa=1e-9, seed {seed}: "
          f"median {1e3 * np.median(t):.2f} ms/scan, max {1e3 * t.max():.1f}, caps {run.caps}")


def many_targets(n_targets: int, clutter_rate: float, n_scans: int, seed: int) -> np.ndarray:
    """Seconds per scan with ``n_targets`` on a grid, uniform clutter, 20 km square."""
    rng = np.random.default_rng(1000 + n_targets)
    half = 10_000.0
    region = Region(-half, half, -half, half)
    side = int(np.ceil(np.sqrt(n_targets)))
    g = np.linspace(-0.7 * half, 0.7 * half, side)
    xy = np.array([(x, y) for x in g for y in g])[:n_targets]
    heading = rng.uniform(0, 2 * np.pi, n_targets)
    targets = tuple(
        Target(id=i + 1, state=(x, 150 * np.cos(h), y, 150 * np.sin(h)), birth=1,
               death=n_scans)
        for i, ((x, y), h) in enumerate(zip(xy, heading, strict=True))
    )
    base = preset("crossing")
    sc = dataclasses.replace(base, name="scale", region=region, scans=(1, n_scans),
                             targets=targets, clutter=UniformClutter(region, clutter_rate))
    assert isinstance(sc, Scenario)
    sim = simulate(sc, seed=seed)
    run = track(MHTTracker(MHTConfig(), KnownClutter(clutter_rate / region.area)), sim.plots)
    return run.seconds_per_scan


def scaling(n_scans: int, seed: int) -> None:
    print(f"scaling ({n_scans} scans, median s/scan, ratio to 10 targets / 10 clutter):")
    ref = float(np.median(many_targets(10, 10, n_scans, seed)))
    for n in (10, 30, 100):
        for lam in (10, 100, 1000):
            t0 = time.perf_counter()
            t = many_targets(n, lam, n_scans, seed)
            med = float(np.median(t))
            print(f"  targets {n:4d} clutter {lam:5d}: median {med:8.4f} s/scan, "
                  f"max {t.max():8.4f}, ratio {med / ref:7.1f}x  "
                  f"(total {time.perf_counter() - t0:.1f} s)")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak resident memory of this process: {peak:.0f} MB")


def burst(seed: int) -> None:
    """One scan of 10 000 uniform plots after 5 ordinary scans: bounded time and memory."""
    import logging

    logging.getLogger("mhtrack.mht.tracker").setLevel(logging.ERROR)
    sc = preset("crossing", clutter="uniform", clutter_rate=40.0, scans=5)
    sim = simulate(sc, seed=seed)
    trk = MHTTracker(MHTConfig(), KnownClutter(40.0 / sc.region.area))
    run = track(trk, sim.plots)
    ordinary = float(np.median(run.seconds_per_scan))
    rng = np.random.default_rng(seed)
    from mhtrack.records import Scan

    big = Scan.from_positions(6, 6.0, rng.uniform(-4000, 4000, (10_000, 2)))
    t0 = time.perf_counter()
    trk.step(big)
    dt = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"burst of 10 000 plots: {dt:.3f} s for that scan ({dt / ordinary:.0f}x an ordinary "
          f"scan), caps {trk.last_stats.caps if trk.last_stats else {}}, "
          f"peak RSS {peak:.0f} MB")


def milp_node_limit(seed: int) -> None:
    """A hard random cluster (300 trees of 1–8 leaves competing for 60 plots per scan):
    ``solve_milp`` with a node limit of 1 (HiGHS's root node only) — its time is what
    one capped cluster costs; the answer is the same on any machine."""
    from mhtrack.mht import solve_milp

    rng = np.random.default_rng(5)
    tree = np.repeat(np.arange(300) * 7 + 3, rng.integers(1, 9, 300))
    window = rng.integers(-1, 60, (tree.size, 3))
    score = np.round(rng.normal(0.5, 2.0, tree.size), 3)
    t0 = time.perf_counter()
    _, exact = solve_milp(score, tree, window, node_limit=1)
    dt = time.perf_counter() - t0
    print(f"MILP on a hard cluster of {tree.size} leaves, node limit 1: {dt:.3f} s, "
          f"proven optimal: {exact}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quick", action="store_true", help="fewer scans in the scaling table")
    ap.add_argument("--skip-scaling", action="store_true")
    a = ap.parse_args(argv)
    crossing_vs_stonesoup(a.seed, 10.0)
    crossing_vs_stonesoup(a.seed, 40.0)
    crossing_default(a.seed)
    burst(a.seed)
    milp_node_limit(a.seed)
    if not a.skip_scaling:
        scaling(10 if a.quick else 30, a.seed)
    return 0


if __name__ == "__main__":
    sys.exit(main())
