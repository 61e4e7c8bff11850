"""Time of each stage of ``MHTTracker.step`` on ``crossing`` (seed 1), unprofiled.

Each stage function that ``mhtrack.mht.tracker`` calls is wrapped in a timer (CPU time of
the process, ``time.process_time``: less sensitive than wall time to the other jobs of a
shared machine); the tracker runs ``--repeat`` times and each stage's least total is
kept. Prints µs per scan and share of the step per stage; the stages of the front of the
cycle (validate … grow, seed, merge) are marked ``F``.

Run: ``PYTHONPATH=src python benchmarks/stage_times.py [mht-agmm|mht-gmm|mht] [--repeat 7]``.
"""

from __future__ import annotations

import argparse
import collections
import time
from collections.abc import Callable
from typing import Any

FRONT = ("validate_scan", "_look", "predict_leaves", "gate_looked", "plots_in_confirmed_gates",
         "update_increment", "miss_increments", "propose_children", "birth.propose",
         "grow_children", "birth.seed", "concat", "merge_by_tree")
STAGES = ("validate_scan", "predict_leaves", "gate_looked", "plots_in_confirmed_gates",
          "clutter_intensity", "update_increment", "miss_increments", "propose_children",
          "prune_children", "grow_children", "number_nodes", "merge_by_tree",
          "best_hypothesis", "prune_after_solve", "hand_over", "confirm", "report",
          "scan_config")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tracker", nargs="?", default="mht-agmm")
    ap.add_argument("--repeat", type=int, default=7)
    a = ap.parse_args()

    import mhtrack.mht.tracker as T
    from mhtrack.build import default_config, make_tracker
    from mhtrack.scenario import preset, simulate

    sc = preset("crossing")
    scans = list(simulate(sc, seed=1).plots.scans())
    acc: dict[str, float] = collections.defaultdict(float)

    def wrap(obj: Any, attr: str, label: str) -> None:
        f: Callable[..., Any] = getattr(obj, attr)

        def timed(*args: Any, **kw: Any) -> Any:
            t = time.process_time()
            out = f(*args, **kw)
            acc[label] += time.process_time() - t
            return out

        setattr(obj, attr, timed)

    for name in STAGES:
        wrap(T, name, name)
    wrap(T.MHTTracker, "_look", "_look")
    wrap(T.MHTTracker, "_forget", "_forget")
    wrap(T.Leaves, "concat", "concat")
    runs = []
    for _ in range(a.repeat):
        acc.clear()
        trk = make_tracker(a.tracker, default_config(sc))
        wrap(trk.birth, "propose", "birth.propose")
        wrap(trk.birth, "seed", "birth.seed")
        t = time.process_time()
        for s in scans:
            trk.step(s)
        runs.append((time.process_time() - t, dict(acc)))
    total = min(t for t, _ in runs)
    least = {k: min(r[k] for _, r in runs) for k in runs[0][1]}
    n = len(scans)
    front = 0.0
    for k, v in sorted(least.items(), key=lambda kv: -kv[1]):
        mark = "  F" if k in FRONT else ""
        front += v if mark else 0.0
        print(f"{k:26s} {v / n * 1e6:8.0f} µs/scan {100 * v / total:5.1f} %{mark}")
    print(f"{a.tracker}: front {front / n * 1e6:.0f} µs/scan ({100 * front / total:.1f} %), "
          f"step {total / n * 1e3:.3f} ms/scan (CPU time, least of {a.repeat}, {n} scans)")


if __name__ == "__main__":
    main()
