"""Asynchronous plots of rotating radars: mhtrack against Stone Soup, and throughput.

**Comparison** (default, issue 14 item 6): the ``opensky-radars`` preset (real OpenSky
aircraft, three rotating radars with their own periods, noises, ``P_D`` and clutter),
simulated with ``--seed``, tracked on the *same* timed plots by mhtrack (``mht-agmm``, built
as ``mhtrack track --sensors`` builds it) and by Stone Soup's GNN and JPDA
(``stonesoup_timed.py``: per-detection timestamps and the plots' own converted
covariances). Every output is scored by ``mhtrack.metrics.evaluate`` at the truth's times
(OSPA c = 2000 m, p = 2), in two like-for-like views:

* online — mhtrack's rows as reported at each frame (``tracks.online()``) against Stone
  Soup's live view (each step's tracks, their state at that step);
* history — mhtrack's history output (confirmed tracks back to their first plot) against
  Stone Soup's whole histories (``track.states`` of every track ever held).

Wall time is the tracker's alone (simulation and building Stone Soup's detections
excluded). Stone Soup is slow on this data (its multi-measurement initiator predicts every
held plot to every new plot), so ``--scans`` (of 10 s) cuts the 20 minutes to a slice;
every tracker runs on that same slice.

**Throughput** (``--hour``): an hour of three radars from the tests' generator
(``tests/mht/async_fixture.py``), target ≤ 60 s on the project's 2-core machine.

Run::

    PYTHONPATH=src python benchmarks/bench_async.py [--scans 12] [--seed 1]
    PYTHONPATH=src python benchmarks/bench_async.py --hour [--duration 3600]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "mht"))

from mhtrack.build import default_config, make_tracker, plots_area  # noqa: E402
from mhtrack.experiments.pipeline import track  # noqa: E402
from mhtrack.metrics import evaluate  # noqa: E402
from mhtrack.mht import MHTConfig  # noqa: E402
from mhtrack.records import TrackTable, TruthTable  # noqa: E402
from mhtrack.scenario import preset, simulate  # noqa: E402

CUTOFF = 2000.0
ORDER = 2.0


def score(tracks: TrackTable, truth: TruthTable) -> tuple[float, float, int]:
    """``(OSPA mean, coverage, track ids)`` at the truth's times (c = 2000 m, p = 2)."""
    e = evaluate(tracks, truth, cutoff=CUTOFF, order=ORDER, at="truth-times")
    return e.ospa_mean, e.coverage, e.n_track_ids


def compare(a: argparse.Namespace) -> None:
    """mhtrack and Stone Soup on the same ``opensky-radars`` plots (module docstring)."""
    from stonesoup_timed import run_stonesoup_timed

    sc = preset("opensky-radars", scans=a.scans or None)
    sim = simulate(sc, seed=a.seed)
    plots, truth = sim.plots, sim.truth
    n_scans = sc.last - sc.first + 1
    print(f"opensky-radars seed {a.seed}, {n_scans} scans ({n_scans * sc.T:.0f} s): "
          f"{len(plots)} plots, {plots.n_scans} frames, "
          f"{np.unique(truth.target_id).size} aircraft")
    # as `mhtrack track plots.csv --sensors sensors.toml` builds it (no scenario)
    cfg = default_config(area=plots_area(plots.x, plots.y).area)
    trk = make_tracker("mht-agmm", cfg, sensors=sc.sensor_set())
    t0 = time.perf_counter()
    run = track(trk, plots, name="mht-agmm", output="history")
    results = {"mhtrack": (time.perf_counter() - t0, run.tracks.online(), run.tracks)}
    pd = {s.id: float(p) for s, p in zip(sc.sensors, sc.pd, strict=True)}
    # mean clutter density of each radar over its disc (per m² per look): uniform + patch
    kappa = {s.id: (s.clutter_rate + sum(p.rate for p in s.clutter_patches))
             / (math.pi * s.max_range**2) for s in sc.sensors}
    for kind in a.stonesoup:
        r = run_stonesoup_timed(plots, pd=pd, clutter_density=kappa, kind=kind, q=a.q,
                                grouping=a.grouping, min_points=a.min_points)
        results[f"stonesoup-{kind}"] = (r.wall, r.online, r.history)
    print(f"\n{'tracker':16s} {'view':8s} {'OSPA (m)':>9s} {'coverage':>9s} {'ids':>5s} "
          f"{'wall (s)':>9s}")
    best: dict[str, dict[str, float]] = {"online": {}, "history": {}}
    for name, (wall, online, history) in results.items():
        for view, tt in (("online", online), ("history", history)):
            o, c, n = score(tt, truth)
            best[view][name] = o
            print(f"{name:16s} {view:8s} {o:9.1f} {c:9.3f} {n:5d} {wall:9.2f}")
    others = [k for k in results if k != "mhtrack"]
    if not others:
        return
    fastest = min(results[k][0] for k in others)
    print()
    for view in ("online", "history"):
        ss = min(best[view][k] for k in others)
        print(f"{view:8s}: OSPA mhtrack / Stone Soup's best = {best[view]['mhtrack']:.1f} / "
              f"{ss:.1f} = {best[view]['mhtrack'] / ss:.3f}  (target <= 0.6)")
    print(f"wall: Stone Soup's fastest / mhtrack = {fastest:.2f} / {results['mhtrack'][0]:.2f}"
          f" = {fastest / results['mhtrack'][0]:.1f}x  (target >= 10)")


#: The tracker configuration of the hour of radars (:func:`hour_scene`).
HOUR_CONFIG = {"new_target_density": 1e-12, "imm_sigma_v": 0.0}


def hour_scene(duration: float, targets: int = 20, seed: int = 1) -> Any:
    """The three rotating radars (periods 4, 8, 12 s) and ``targets`` targets of the hour
    benchmark, simulated for ``duration`` s by the tests' generator (``AsyncSim``)."""
    from async_fixture import Radar, default_targets, simulate_async

    radars = [
        Radar(1, -60_000.0, -20_000.0, period=4.0, phase_deg=10.0, max_range=400_000.0,
              clutter_per_rotation=15.0),
        Radar(2, 50_000.0, 40_000.0, period=8.0, phase_deg=200.0, pd=0.85,
              sigma_range=60.0, sigma_bearing_deg=0.2, max_range=400_000.0,
              clutter_per_rotation=20.0),
        Radar(3, 0.0, -80_000.0, period=12.0, phase_deg=95.0, pd=0.8, sigma_range=80.0,
              sigma_bearing_deg=0.25, max_range=400_000.0, clutter_per_rotation=25.0),
    ]
    x0 = default_targets(targets, seed=seed, extent=100_000.0, speeds=(30.0, 90.0))
    return simulate_async(radars, x0, duration=duration, seed=seed)


def throughput(a: argparse.Namespace) -> dict[str, float]:
    """An hour (``--duration``) of three rotating radars from the tests' generator; the
    figures (also printed) as a dict."""
    sim = hour_scene(a.duration, a.targets, a.seed)
    plots = sim.plots
    trk = make_tracker(a.tracker, MHTConfig(**HOUR_CONFIG), sensors=sim.sensors)
    t0 = time.perf_counter()
    tracks = trk.run(plots)
    wall = time.perf_counter() - t0
    on = tracks.online()
    followed, false = set(), 0
    for tid in np.unique(on.track_id).tolist():
        r = on.take(on.track_id == tid)
        step = max(len(r) // 50, 1)
        truth = np.array([sim.truth_at(t) for t in r.time[::step]])
        rr = r.take(np.arange(len(r))[::step])
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
    return {"wall_s": wall, "plots": len(plots), "frames": plots.n_scans,
            "followed": len(followed), "targets": a.targets}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scans", type=int, default=12,
                    help="opensky-radars scans of 10 s to track, 0: all (Stone Soup is slow)")
    ap.add_argument("--stonesoup", nargs="*", default=["gnn", "jpda"],
                    choices=["gnn", "jpda"], help="Stone Soup trackers to run")
    ap.add_argument("--q", type=float, default=1.0,
                    help="Stone Soup CV process-noise intensity (m²/s³)")
    ap.add_argument("--min-points", type=int, default=3,
                    help="plots of a Stone Soup track before its initiator releases it")
    ap.add_argument("--grouping", choices=["frame", "time"], default="frame",
                    help="Stone Soup steps: one per frame, or per distinct plot time")
    ap.add_argument("--hour", action="store_true", help="throughput benchmark instead")
    ap.add_argument("--duration", type=float, default=3600.0)
    ap.add_argument("--targets", type=int, default=20)
    ap.add_argument("--tracker", default="mht-gmm")
    a = ap.parse_args()
    if a.hour:
        throughput(a)
    else:
        compare(a)


if __name__ == "__main__":
    main()
