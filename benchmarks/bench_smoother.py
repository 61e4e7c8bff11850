"""Cost of the smoothed history (``--output smoothed``) against the tracking in the same run.

Simulates ``opensky-radars`` (three rotating radars, 20 minutes) for each seed, tracks it
through the pipeline keeping the rows' model states (what ``--output smoothed`` keeps),
then times :func:`mhtrack.sinks.smoothed.smoothed_rows` on the run's history. Prints, per
seed: rows, tracks, the tracker's time (sum of its steps), the smoother's time, their
ratio, and the memory the kept rows take (with their model states).

Run::

    PYTHONPATH=src python benchmarks/bench_smoother.py [--seeds 1 2 3]
"""

from __future__ import annotations

import argparse
import time

from mhtrack.pipeline import Pipeline, TrackOptions
from mhtrack.scenario import preset, simulate
from mhtrack.sinks import TrackCollector
from mhtrack.sinks.smoothed import smoothed_rows
from mhtrack.sources.memory import MemorySource


def measure(seed: int) -> dict[str, float]:
    sc = preset("opensky-radars")
    sim = simulate(sc, seed=seed)
    pipe = Pipeline(MemorySource(sim.plots, sensors=sc.sensor_set()),
                    TrackOptions(output="history"))
    pipe.tracker.keep_models = True
    rows = TrackCollector("history")
    result = pipe.run([rows], keep_stats=False)
    history = rows.tracks()
    t0 = time.perf_counter()
    smoothed_rows(history, pipe.tracker.motion)
    t_smooth = time.perf_counter() - t0
    assert result.summary is not None
    kept = sum(a.nbytes for a in (history.x, history.y, history.vx, history.vy, history.time,
                                  history.P, history.mu, history.xm, history.Pm) if a is not None)
    return {"rows": len(history), "tracks": result.n_tracks,
            "track_s": result.summary.time_s, "smooth_s": t_smooth, "kept_MB": kept / 1e6}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    args = ap.parse_args()
    print("| seed | rows | tracks | tracking (s) | smoothing (s) | ratio | rows kept (MB) |")
    print("|---|---|---|---|---|---|---|")
    for seed in args.seeds:
        m = measure(seed)
        print(f"| {seed} | {m['rows']} | {m['tracks']} | {m['track_s']:.1f} | "
              f"{m['smooth_s']:.2f} | {m['smooth_s'] / m['track_s']:.3f} | "
              f"{m['kept_MB']:.1f} |", flush=True)


if __name__ == "__main__":
    main()
