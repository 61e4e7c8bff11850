"""A clutter burst: one scan of ~100 000 plots from two radars, through ``mhtrack track``
(issue 16 item 3: peak RSS ≤ 2 GB, wall ≤ 60 s, and the caps it reports).

The plots file: the ``opensky`` preset (two polar radars over a 520 × 550 km region),
5 scans simulated with seed 1, whose third scan is replaced by the same scan simulated
with uniform clutter at ``N/2`` plots per radar (seed 2) — with polar plots
(range/bearing, so every plot has its own covariance) and the scenario TOML beside it.
``--scene multiradar`` puts the burst into the ``multiradar`` preset's first two radars
instead (a 14 km square: a dense burst, hundreds of plots within each plot's gate).

``mhtrack track`` runs as a subprocess; its peak resident memory is
``resource.getrusage(RUSAGE_CHILDREN).ru_maxrss`` (the largest child's) and its wall time
the subprocess's. The caps the run reports (its warning lines on stderr) are printed beside.

Run: ``python benchmarks/bench_burst.py [--plots 100000] [--scene opensky|multiradar]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def make_files(out: Path, n_plots: int, scene: str, seed: int = 1) -> int:
    """Write ``out/plots.csv`` and ``out/scenario.toml`` (module docstring); returns the
    number of plots of the burst scan."""
    from mhtrack.io import write_plots, write_scenario_toml
    from mhtrack.records import PlotTable
    from mhtrack.scenario import preset, simulate
    from mhtrack.scenario.overrides import apply_overrides

    sc = preset(scene, scans=5)
    if len(sc.sensors) > 2:
        sc = dataclasses.replace(sc, sensors=sc.sensors[:2], pd=tuple(sc.pd[:2]))
    base = simulate(sc, seed=seed).plots
    burst = simulate(apply_overrides(sc, clutter="uniform", clutter_rate=n_plots / 2),
                     seed=seed + 1).plots
    k = sc.first + 2
    a, b = base.scan != k, burst.scan == k
    order = np.argsort(np.concatenate([base.scan[a], burst.scan[b]]), kind="stable")

    def cat(name: str) -> np.ndarray | None:
        u, v = getattr(base, name), getattr(burst, name)
        return None if u is None else np.concatenate([u[a], v[b]])[order]

    cols = ("scan", "time", "sensor", "x", "y", "range", "bearing", "origin", "R")
    write_plots(PlotTable(**{c: cat(c) for c in cols}), out / "plots.csv")
    write_scenario_toml({"seed": seed, **sc.to_dict()}, out / "scenario.toml")
    return int(b.sum())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plots", type=int, default=100_000, help="plots of the burst scan")
    ap.add_argument("--scene", choices=("opensky", "multiradar"), default="opensky")
    ap.add_argument("--tracker", default="mht-agmm")
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        n = make_files(d, a.plots, a.scene)
        cmd = [sys.executable, "-c", "from mhtrack.cli.main import main; main()", "track",
               str(d / "plots.csv"),
               "--scenario", str(d / "scenario.toml"), "--out", str(d / "tracks.csv"),
               "--tracker", a.tracker, "--no-progress"]
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True, env=os.environ.copy())
        wall = time.perf_counter() - t0
    rss = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"burst: {a.scene}, 2 radars, one scan of {n} plots (5 scans), {a.tracker}")
    print(f"  mhtrack track: exit {p.returncode}, wall {wall:.1f} s, peak RSS {rss:.0f} MB "
          f"(bounds: 60 s, 2048 MB)")
    for line in (p.stderr + p.stdout).splitlines():
        if "caps" in line or "Error" in line or "error" in line:
            print("  " + line)
    return p.returncode


if __name__ == "__main__":
    sys.exit(main())
