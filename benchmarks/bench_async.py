"""Throughput of the MHT on asynchronous plots: three rotating radars for an hour.

Target of issue 14: an hour of three radars (~60 000 plots) tracked in at most 60 s on
the project's 2-core machine. The plots come from the tests' self-contained generator
(``tests/mht/async_fixture.py``: radars rotating clockwise with their own periods and
phases, each plot timed when the beam crossed it, polar errors converted with their
covariance, clutter uniform in range and azimuth). Run::

    PYTHONPATH=src python benchmarks/bench_async.py [--duration 3600] [--tracker mht-gmm]

It prints plots, frames, wall time, the ratio to real time and the confirmed tracks
against the targets (a track follows a target when its median distance is under 500 m).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "mht"))

from async_fixture import Radar, default_targets, simulate_async

from mhtrack.build import make_tracker
from mhtrack.mht import MHTConfig

RADARS = [
    Radar(1, -60_000.0, -20_000.0, period=4.0, phase_deg=10.0, max_range=400_000.0,
          clutter_per_rotation=15.0),
    Radar(2, 50_000.0, 40_000.0, period=8.0, phase_deg=200.0, pd=0.85, sigma_range=60.0,
          sigma_bearing_deg=0.2, max_range=400_000.0, clutter_per_rotation=20.0),
    Radar(3, 0.0, -80_000.0, period=12.0, phase_deg=95.0, pd=0.8, sigma_range=80.0,
          sigma_bearing_deg=0.25, max_range=400_000.0, clutter_per_rotation=25.0),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=3600.0)
    ap.add_argument("--targets", type=int, default=20)
    ap.add_argument("--tracker", default="mht-gmm")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    x0 = default_targets(a.targets, seed=a.seed, extent=100_000.0, speeds=(30.0, 90.0))
    sim = simulate_async(RADARS, x0, duration=a.duration, seed=a.seed)
    plots = sim.plots
    trk = make_tracker(a.tracker, MHTConfig(new_target_density=1e-12, imm_sigma_v=0.0),
                       sensors=sim.sensors)
    t0 = time.perf_counter()
    tracks = trk.run(plots)
    wall = time.perf_counter() - t0
    on = tracks.online()
    followed, false = set(), 0
    for tid in np.unique(on.track_id).tolist():
        r = on.take(on.track_id == tid)
        truth = np.array([sim.truth_at(t) for t in r.time[:: max(len(r) // 50, 1)]])
        rr = r.take(np.arange(len(r))[:: max(len(r) // 50, 1)])
        d = np.median(np.hypot(truth[:, :, 0] - rr.x[:, None], truth[:, :, 1] - rr.y[:, None]),
                      axis=0)
        if d.min() < 500.0:
            followed.add(int(d.argmin()))
        else:
            false += 1
    print(f"plots {len(plots)}  frames {plots.n_scans}  data {a.duration:.0f} s  "
          f"wall {wall:.1f} s  ({a.duration / wall:.0f}x real time, "
          f"{1e3 * wall / plots.n_scans:.2f} ms/frame)")
    print(f"targets {a.targets}: followed {len(followed)}, track ids "
          f"{np.unique(on.track_id).size}, false tracks {false}")


if __name__ == "__main__":
    main()
