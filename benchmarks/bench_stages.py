"""Where a scan's time goes: CPU time of each stage of ``MHTTracker.step``.

Each function the tracker's ``step`` calls (``mhtrack.mht.tracker``'s names, the birth
process's ``propose``/``seed``, the history, the statistics) is wrapped in a
``time.process_time`` timer (CPU time of this process: less disturbed by other jobs on a
shared machine than the wall clock; the wrapper adds ~1 µs a call). Scenes:

* ``crossing`` — P1's crossing, seed 1, as ``mhtrack run crossing`` builds ``--tracker``;
* ``hour`` — ``--duration`` s of the three rotating radars of ``bench_async.py --hour``;
* ``big`` — ``--scans`` scans of 1 000 targets in 5 000 clutter plots (``bench_scale.py``).

The best of ``--repeat`` runs is printed, stage by stage, in µs per scan and share.

Run::

    PYTHONPATH=src python benchmarks/bench_stages.py crossing --tracker mht-gmm
    PYTHONPATH=src python benchmarks/bench_stages.py hour --duration 600
    PYTHONPATH=src python benchmarks/bench_stages.py big --scans 5 --repeat 1
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "mht"))

import mhtrack.mht.tracker as T  # noqa: E402

#: The tracker module's names, in the order of the cycle, and the stage they time.
STAGES = ["validate_scan", "predict_leaves", "gate_looked",
          "plots_in_confirmed_gates", "clutter_intensity", "update_increment",
          "miss_increments", "propose_children", "prune_children", "grow_children",
          "number_nodes", "merge_by_tree", "number_and_merge", "number_frame", "best_hypothesis",
          "removed_after_solve", "prune_after_solve", "kept_after_solve", "take_kept",
          "hand_over", "confirm",
          "newly_confirmed", "report", "confirmed_windows"]
ACC: dict[str, float] = {}


def _timed(name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
    def wrapper(*a: Any, **k: Any) -> Any:
        t = time.process_time()
        try:
            return fn(*a, **k)
        finally:
            ACC[name] = ACC.get(name, 0.0) + time.process_time() - t
    return wrapper


def install() -> None:
    """Wrap every stage (module docstring)."""
    for name in STAGES:
        if hasattr(T, name):  # the names of the version on PYTHONPATH
            setattr(T, name, _timed(name, getattr(T, name)))
    for cls, names in ((T.MHTTracker, ("_look", "_forget")),
                       (T.TentativeHistory, ("backfill", "record")), (T.SPRT, ("confirms",))):
        for n in names:
            setattr(cls, n, _timed(f"{cls.__name__}.{n}", getattr(cls, n)))
    for cls, n in ((T.Reported, "of"), (T.StepStats, "of"), (T.Leaves, "concat")):
        setattr(cls, n, classmethod(_timed(f"{cls.__name__}.{n}", getattr(cls, n).__func__)))


def scene(a: argparse.Namespace) -> tuple[Callable[[], Any], list]:
    """``(make a tracker, the scans)`` of the scene ``a.scene``."""
    from mhtrack.build import default_config, make_tracker
    from mhtrack.scenario import preset, simulate

    if a.scene == "crossing":
        sc = preset("crossing")
        scans = list(simulate(sc, seed=1).plots.scans())
        return (lambda: make_tracker(a.tracker, default_config(sc))), scans
    if a.scene == "hour":
        from bench_async import HOUR_CONFIG, hour_scene
        from mhtrack.mht import MHTConfig

        sim = hour_scene(a.duration)  # as bench_async.py --hour
        cfg = MHTConfig(**HOUR_CONFIG)
        return (lambda: make_tracker("mht-gmm", cfg, sensors=sim.sensors)), list(
            sim.plots.scans())
    import logging

    from bench_scale import SCENES
    from bench_scale import scene as scale_scene

    logging.getLogger("mhtrack").setLevel(logging.ERROR)
    n_targets, rate, tracker = SCENES["big"]
    sc = scale_scene(n_targets, rate, a.scans)
    cfg = dataclasses.replace(default_config(sc), scale_caps=True)
    return (lambda: make_tracker(tracker, cfg, clutter_density=rate / sc.region.area)), list(
        simulate(sc, seed=1).plots.scans())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", choices=["crossing", "hour", "big"])
    ap.add_argument("--tracker", default="mht-agmm", help="crossing: the tracker")
    ap.add_argument("--duration", type=float, default=600.0, help="hour: seconds of data")
    ap.add_argument("--scans", type=int, default=5, help="big: scans")
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    make, scans = scene(a)
    install()
    best: dict[str, float] | None = None
    for _ in range(a.repeat):
        ACC.clear()
        trk = make()
        trk.birth.propose = _timed("Birth.propose", trk.birth.propose)
        trk.birth.seed = _timed("Birth.seed", trk.birth.seed)
        t = time.process_time()
        for s in scans:
            trk.step(s)
        total = time.process_time() - t
        if best is None or total < best["step"]:
            best = {**ACC, "step": total}
    assert best is not None
    n = len(scans)
    total = best.pop("step")
    print(f"{a.scene} ({n} scans): step {1e6 * total / n:.0f} µs/scan, CPU, best of "
          f"{a.repeat}")
    for k, v in sorted(best.items(), key=lambda kv: -kv[1]):
        print(f"  {k:26s} {1e6 * v / n:9.1f} µs/scan {100 * v / total:5.1f} %")


if __name__ == "__main__":
    main()
