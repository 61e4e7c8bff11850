"""cProfile of a tracker's steps on ``crossing`` (where the calls go; not a speed figure)::

    PYTHONPATH=src python benchmarks/profile_crossing.py mht-agmm tottime
    PYTHONPATH=src python benchmarks/profile_crossing.py mht-gmm          # total only

The tracker is built as ``mhtrack run crossing`` builds it; only ``step`` is timed.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time

from mhtrack.build import default_config, make_tracker
from mhtrack.scenario import preset, simulate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tracker", nargs="?", default="mht-agmm")
    ap.add_argument("sort", nargs="?", help="pstats sort key (tottime, cumtime, ...)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--lines", type=int, default=45)
    a = ap.parse_args()
    sc = preset("crossing")
    scans = list(simulate(sc, seed=a.seed).plots.scans())
    tracker = make_tracker(a.tracker, default_config(sc))
    prof = cProfile.Profile() if a.sort else None
    t = time.perf_counter()
    if prof:
        prof.enable()
    for s in scans:
        tracker.step(s)
    if prof:
        prof.disable()
        pstats.Stats(prof).sort_stats(a.sort).print_stats(a.lines)
    dt = time.perf_counter() - t
    print(f"{a.tracker}: {len(scans)} scans, {1e3 * dt / len(scans):.3f} ms/scan"
          f"{' (under cProfile)' if prof else ''}")


if __name__ == "__main__":
    main()
