"""Caps that scale with the scene (issue 18 item 3): many targets in heavy clutter with the
tracker's default settings.

Two scenes, targets on a grid in a 100 km square with uniform clutter, every scan a new
draw (``numpy`` seed fixed):

* **1 000 targets × 5 000 clutter plots per scan**, the plain MHT with the true clutter
  density (``KnownClutter``): seconds per scan, the share of targets confirmed (a
  confirmed track within 300 m of the target at the last scan), peak resident memory;
* **10 targets × 5 000 clutter plots per scan**, MHT-AGMM (clutter estimated online).

Each scene runs in its own subprocess so that its peak RSS (``ru_maxrss``) is its own.
Every run prints the caps that acted (``StepStats.caps``: scans and counts) beside the
limits the scene's size gave (:func:`mhtrack.mht.caps.scaled_limits`).

Run: ``python benchmarks/bench_scale.py [--scans 10] [--scene big|agmm] [--fixed-caps]``.
Timings are noisy on a shared machine; ``docs/performance.md`` says when they were taken.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import resource
import subprocess
import sys
import time

import numpy as np

SCENES = {"big": (1000, 5000.0, "mht"), "agmm": (10, 5000.0, "mht-agmm")}


def scene(n_targets: int, clutter_rate: float, n_scans: int) -> object:
    """Targets on a grid in a 100 km square moving at 150 m/s, uniform clutter (5 000
    plots per scan: 5·10⁻⁷ per m², the density of P1's crossing)."""
    from mhtrack.models.clutter import Region, UniformClutter
    from mhtrack.scenario import Target, preset

    rng = np.random.default_rng(1000 + n_targets)
    half = 50_000.0
    region = Region(-half, half, -half, half)
    side = int(np.ceil(np.sqrt(n_targets)))
    g = np.linspace(-0.7 * half, 0.7 * half, side)
    xy = np.array([(x, y) for x in g for y in g])[:n_targets]
    heading = rng.uniform(0, 2 * np.pi, n_targets)
    targets = tuple(
        Target(id=i + 1, state=(x, 150 * np.cos(h), y, 150 * np.sin(h)), birth=1,
               death=n_scans)
        for i, ((x, y), h) in enumerate(zip(xy, heading, strict=True)))
    return dataclasses.replace(preset("crossing"), name="scale", region=region,
                               scans=(1, n_scans), targets=targets,
                               clutter=UniformClutter(region, clutter_rate))


def run_one(name: str, n_scans: int, seed: int, fixed: bool = False) -> dict:
    """One scene in this process: the figures as a dict."""
    import logging

    from mhtrack.build import default_config, make_tracker
    from mhtrack.experiments import track
    from mhtrack.scenario import simulate

    logging.getLogger("mhtrack").setLevel(logging.ERROR)
    n_targets, rate, tracker = SCENES[name]
    sc = scene(n_targets, rate, n_scans)
    sim = simulate(sc, seed=seed)
    cfg = dataclasses.replace(default_config(sc), scale_caps=not fixed)
    kappa = rate / sc.region.area
    trk = make_tracker(tracker, cfg, clutter_density=kappa if tracker == "mht" else None)
    t0 = time.perf_counter()
    run = track(trk, sim.plots, name=tracker, output="online")
    wall = time.perf_counter() - t0
    last = int(sim.truth.scan.max())
    tr = run.tracks.take(np.flatnonzero(run.tracks.scan == last))
    tt = np.flatnonzero(sim.truth.scan == last)
    found = 0
    if len(tr) and len(tt):
        from scipy.spatial import cKDTree

        d, _ = cKDTree(tr.positions).query(sim.truth.positions[tt])
        found = int(np.count_nonzero(d <= 300.0))
    per_scan = run.seconds_per_scan
    return {"scene": name, "tracker": tracker, "caps_rule": "fixed" if fixed else "scaled",
            "targets": n_targets, "clutter": rate,
            "scans": n_scans, "plots_per_scan": len(sim.plots) / n_scans,
            "s_per_scan_median": float(np.median(per_scan)),
            "s_per_scan_mean": float(per_scan.mean()), "wall_s": wall,
            "coverage": found / max(len(tt), 1),
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "caps": run.caps, "cap_scans": run.cap_scans,
            "limits_last_scan": run.stats[-1].limits if run.stats else {}}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scans", type=int, default=10)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scene", choices=sorted(SCENES), default=None,
                    help="one scene in this process (default: each in a subprocess)")
    ap.add_argument("--fixed-caps", action="store_true",
                    help="MHTConfig(scale_caps=False): the caps of before, for comparison")
    a = ap.parse_args(argv)
    if a.scene is not None:
        print(json.dumps(run_one(a.scene, a.scans, a.seed, a.fixed_caps)))
        return 0
    for name in ("big", "agmm"):
        out = subprocess.run([sys.executable, __file__, "--scene", name, "--scans",
                              str(a.scans), "--seed", str(a.seed)]
                             + (["--fixed-caps"] if a.fixed_caps else []),
                             capture_output=True, text=True, check=True)
        r = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"{r['targets']} targets x {r['clutter']:g} clutter/scan, {r['tracker']}, "
              f"{r['caps_rule']} caps, "
              f"{r['scans']} scans ({r['plots_per_scan']:.0f} plots/scan): "
              f"median {r['s_per_scan_median']:.3f} s/scan (mean {r['s_per_scan_mean']:.3f}), "
              f"coverage {r['coverage']:.3f}, peak RSS {r['peak_rss_mb']:.0f} MB")
        print(f"  caps acted: {r['caps'] or 'none'}; scans: {r['cap_scans'] or '-'}")
        print(f"  limits at the last scan: {r['limits_last_scan']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
