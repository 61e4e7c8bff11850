"""The birth processes on ``opensky-radars`` (timed plots of three rotating radars; issue 28,
item 7): per seed and ``--birth``, coverage, track ids per aircraft, false tracks and OSPA,
each run through the CLI::

    mhtrack simulate opensky-radars --seed S --no-attributes --out D
    mhtrack track D/plots.csv --sensors D/sensors.toml --birth B --out D/tracks_B.csv
    mhtrack evaluate D/tracks_B.csv D/truth.csv --json

A *false track* is a track id none of whose reported rows holds a target's plot (the
``plot`` column's row of ``plots.csv`` has ``origin = -1``, or the row is a miss).
Run: ``PYTHONPATH=src python benchmarks/bench_births.py [--births B,...] [seeds...]``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

BIRTHS = ("every-plot", "logic", "modified-logic", "hough", "modified-hough")


def _cli(*args: str) -> str:
    cmd = [sys.executable, "-c", "from mhtrack.cli.main import main; main()", *args]
    return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout


def false_tracks(tracks: Path, plots: Path) -> int:
    """Track ids none of whose rows holds a target's plot."""
    t = pd.read_csv(tracks, usecols=["track_id", "plot"])
    origin = pd.read_csv(plots, usecols=["origin"])["origin"].to_numpy()
    p = t["plot"].to_numpy(float)  # empty (NaN) on a miss row
    on_target = np.zeros(len(t), bool)
    has = np.isfinite(p) & (p >= 0)
    on_target[has] = origin[p[has].astype(np.int64)] >= 0
    by_id = pd.Series(on_target).groupby(t["track_id"].to_numpy()).any()
    return int((~by_id).sum())


def main(seeds: list[int], births: list[str]) -> None:
    print("| seed | birth | coverage | ids per aircraft | false tracks | OSPA (m) | track (s) |")
    print("|---|---|---|---|---|---|---|")
    for seed in seeds:
        with tempfile.TemporaryDirectory() as tmp:
            d = Path(tmp)
            _cli("simulate", "opensky-radars", "--seed", str(seed), "--no-attributes",
                 "--out", str(d))
            for birth in births:
                out = d / f"tracks_{birth}.csv"
                t0 = time.perf_counter()
                _cli("track", str(d / "plots.csv"), "--sensors", str(d / "sensors.toml"),
                     "--birth", birth, "--out", str(out))
                wall = time.perf_counter() - t0
                m = json.loads(_cli("evaluate", str(out), str(d / "truth.csv"), "--json"))
                print(f"| {seed} | {birth} | {m['coverage']:.3f} | "
                      f"{m['n_track_ids'] / m['n_targets']:.3f} | "
                      f"{false_tracks(out, d / 'plots.csv')} | {m['ospa_mean']:.1f} | "
                      f"{wall:.0f} |", flush=True)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("seeds", nargs="*", type=int, default=[1, 2, 3])
    ap.add_argument("--births", default=",".join(BIRTHS))
    a = ap.parse_args()
    main(a.seeds, a.births.split(","))
