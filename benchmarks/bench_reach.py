"""The learned reach (mhtrack.mht.reach) on opensky-radars with ``max_range`` deleted from
the sensors file (issue 28, item 6): coverage and ids per aircraft of three runs per seed
— the full sensors file, ``max_range`` deleted (every radar sees to infinity), and deleted
with each radar's reach learned from its plots — and the learned reach per radar beside
the true one.

Each run goes through ``mhtrack track``; the "deleted" run switches the learning off
(``RadarCoverage(learn_reach=False)``, every radar seeing to infinity, the former rule).
Run: ``PYTHONPATH=src python benchmarks/bench_reach.py [seeds...]``.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import mhtrack.build
from mhtrack.mht.coverage import RadarCoverage

LEARNED: list[RadarCoverage] = []


class Recorded(RadarCoverage):
    """RadarCoverage that keeps itself for the summary (learning as the run asks)."""

    learn = True

    def __init__(self, sensors, **kw) -> None:  # type: ignore[no-untyped-def]
        super().__init__(sensors, learn_reach=self.learn, **kw)
        LEARNED.append(self)


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
            cli.main(["simulate", "opensky-radars", "--seed", str(seed), "--no-attributes",
                      "--out", str(d)],
                     standalone_mode=False)
            full = (d / "sensors.toml").read_text()
            true = [float(v) for v in re.findall(r"^max_range = (\S+)$", full, re.M)]
            (d / "bare.toml").write_text(re.sub(r"^max_range = .*\n", "", full, flags=re.M))
            rows = []
            for label, sensors, learned in (("full", "sensors.toml", False),
                                            ("no max_range", "bare.toml", False),
                                            ("learned", "bare.toml", True)):
                Recorded.learn = learned
                mhtrack.build.parts.RadarCoverage = Recorded  # type: ignore[misc]
                out = d / f"tracks_{len(rows)}.csv"
                cli.main(["track", str(d / "plots.csv"), "--sensors", str(d / sensors),
                          "--out", str(out)], standalone_mode=False)
                rows.append((label, *_metrics(out, d / "truth.csv")))
            for label, cov, ids in rows:
                print(f"seed {seed} {label:13s} coverage {cov:.4f}  ids/aircraft {ids:.3f}")
            summary = LEARNED[-1].reach.summary()
            for (sid, (lo, med, hi)), r in zip(sorted(summary.items()), true, strict=False):
                print(f"seed {seed} radar {sid}: learned reach min {lo / 1e3:.0f} / median "
                      f"{med / 1e3:.0f} / max {hi / 1e3:.0f} km; true max_range "
                      f"{r / 1e3:.0f} km")


if __name__ == "__main__":
    main([int(s) for s in sys.argv[1:]] or [1, 2, 3])
