"""Per-scan timing of the MHT (not a test; run ``python tests/mht/measure_speed.py``).

Cases: the uniform-clutter crossing fixture with the true κ (40 and 10 clutter/scan) and
with P1's plain κ = 1e−9; 100 targets + 1 000 clutter/scan; a 10 000-plot burst.
"""

from __future__ import annotations

import logging
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from crossing_fixture import random_targets, simulate

from mhtrack.clutter import KnownClutter
from mhtrack.mht import MHTConfig, MHTTracker, StepStats
from mhtrack.records import Scan


def timed(sim, kappa: float) -> list[StepStats]:
    stats: list[StepStats] = []
    MHTTracker(MHTConfig(), KnownClutter(kappa)).run(sim.scans, stats)
    return stats


def report(name: str, stats: list[StepStats]) -> None:
    t = np.array([s.time_s for s in stats]) * 1e3
    leaves = np.array([s.n_leaves for s in stats])
    capped = sum(bool(s.caps) for s in stats)
    print(f"{name:48s} median {np.median(t):7.2f} ms  p90 {np.percentile(t, 90):7.2f} ms  "
          f"max {t.max():7.1f} ms  leaves median {int(np.median(leaves)):6d}  "
          f"scans with caps {capped}/{len(stats)}")


def main() -> None:
    logging.disable(logging.WARNING)
    for rate in (40.0, 10.0):
        sim = simulate(clutter_rate=rate, seed=1)
        report(f"crossing, {rate:.0f} clutter/scan, true κ", timed(sim, sim.clutter_density))
    sim = simulate(clutter_rate=40.0, seed=1)
    report("crossing, 40 clutter/scan, κ = 1e-9", timed(sim, 1e-9))
    dense = simulate(random_targets(100, 20, 5), n_scans=20, clutter_rate=1000.0, seed=3)
    report("100 targets + 1000 clutter/scan, true κ", timed(dense, dense.clutter_density))
    report("100 targets + 1000 clutter/scan, κ = 1e-9", timed(dense, 1e-9))
    trk = MHTTracker(MHTConfig(), KnownClutter(sim.clutter_density))
    trk.run(sim.scans[:40])
    rng = np.random.default_rng(0)
    for k in (41, 42):
        burst = Scan.from_positions(k, float(k), rng.uniform(-4000, 4000, (10_000, 2)))
        t0 = time.perf_counter()
        trk.step(burst)
        print(f"burst of 10 000 plots at scan {k}: {time.perf_counter() - t0:.3f} s, "
              f"caps {trk.last_stats.caps}")
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak RSS of this process: {rss:.0f} MB")


if __name__ == "__main__":
    main()
