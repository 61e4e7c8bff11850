"""The learned reach (mhtrack.mht.reach) on opensky-radars with ``max_range`` deleted from
the sensors file (issue 28, item 6): coverage and ids per aircraft of three runs per seed
— the full sensors file, ``max_range`` deleted (every radar sees to infinity), and deleted
with each radar's reach learned from its plots — and the learned reach per radar beside
the true one.

Until the coverage stage takes the estimator (after the mht/ refactor), this script plugs
it in with a subclass of RadarCoverage: each frame's plots update the radar's reach, then
a leaf beyond it is not charged a miss (its look is not certain; a plot may still update
it). Run: ``PYTHONPATH=src python benchmarks/bench_reach.py [seeds...]``.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import mhtrack.build
from mhtrack.mht.coverage import Looks, RadarCoverage, grid_bearing
from mhtrack.mht.reach import ReachEstimator

LEARNED: list[ReachEstimator] = []


class LearnedReachCoverage(RadarCoverage):
    """RadarCoverage whose radars without ``max_range`` use their learned reach."""

    def __init__(self, sensors, **kw) -> None:  # type: ignore[no-untyped-def]
        super().__init__(sensors, **kw)
        self.reach = ReachEstimator({s.id: s.period for s in sensors.sensors if s.period})
        LEARNED.append(self.reach)

    def detection(self, scan, x, P, time):  # type: ignore[no-untyped-def]
        sid = self._sensor_id(scan)
        site = self._site_of(sid)
        looks = super().detection(scan, x, P, time)
        if site is None or self.sensors.sensor(sid).max_range is not None:
            return looks
        z = np.asarray(scan.z, float).reshape(-1, 2)
        self.reach.update(sid, scan.plot_times(), np.hypot(z[:, 0] - site[0],
                                                           z[:, 1] - site[1]),
                          grid_bearing(z[:, 0] - site[0], z[:, 1] - site[1]))
        x = np.asarray(x, float).reshape(-1, 4)
        dt = float(scan.time) - np.asarray(time, float)
        px = x[:, 0] + x[:, 1] * dt - site[0]
        py = x[:, 2] + x[:, 3] * dt - site[1]
        inside = self.reach.within(sid, np.hypot(px, py), grid_bearing(px, py))
        return Looks(looks.pd, looks.certain & inside)


def _metrics(tracks: Path, truth: Path) -> tuple[float, float]:
    out = subprocess.run(["mhtrack", "evaluate", str(tracks),
                          str(truth), "--json"], capture_output=True, text=True, check=True)
    d = json.loads(out.stdout)
    return d["coverage"], d["n_track_ids"] / d["n_targets"]


def main(seeds: list[int]) -> None:
    from mhtrack.cli.main import cli

    for seed in seeds:
        with tempfile.TemporaryDirectory() as tmp:
            d = Path(tmp)
            cli.main(["simulate", "opensky-radars", "--seed", str(seed), "--out", str(d)],
                     standalone_mode=False)
            full = (d / "sensors.toml").read_text()
            true = [float(v) for v in re.findall(r"^max_range = (\S+)$", full, re.M)]
            (d / "bare.toml").write_text(re.sub(r"^max_range = .*\n", "", full, flags=re.M))
            rows = []
            for label, sensors, learned in (("full", "sensors.toml", False),
                                            ("no max_range", "bare.toml", False),
                                            ("learned", "bare.toml", True)):
                mhtrack.build.RadarCoverage = LearnedReachCoverage if learned \
                    else RadarCoverage  # type: ignore[misc]
                out = d / f"tracks_{len(rows)}.csv"
                cli.main(["track", str(d / "plots.csv"), "--sensors", str(d / sensors),
                          "--out", str(out)], standalone_mode=False)
                rows.append((label, *_metrics(out, d / "truth.csv")))
            for label, cov, ids in rows:
                print(f"seed {seed} {label:13s} coverage {cov:.4f}  ids/aircraft {ids:.3f}")
            summary = LEARNED[-1].summary()
            for (sid, (lo, med, hi)), r in zip(sorted(summary.items()), true, strict=False):
                print(f"seed {seed} radar {sid}: learned reach min {lo / 1e3:.0f} / median "
                      f"{med / 1e3:.0f} / max {hi / 1e3:.0f} km; true max_range "
                      f"{r / 1e3:.0f} km")


if __name__ == "__main__":
    main([int(s) for s in sys.argv[1:]] or [1, 2, 3])
