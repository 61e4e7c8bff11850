"""Issue 30, item 5: what ``live --release radar`` and ``live --sector-frames`` change
(``docs/live.md``, *Latency*) — rows and quality on ``opensky-radars`` seed 1 against the
default (``--release time``, whose rows equal ``track --output online`` on the
recording).

    python benchmarks/release_order.py [--out DIR] [--scans N] [--frames eighth sector]

The scene is simulated and exported as a raw ``.ast`` recording, then fed to ``mhtrack
live --stdin raw --day-from stream --json`` once per release and framing (a file as stdin: no wall
clock enters, the same rows every run); ``track --output online`` on the same recording
beside them. Each output goes through :mod:`bench_live_feed`'s conversion to a tracks
file and ``mhtrack evaluate --json``: rows, OSPA (mean), coverage, track ids, id switches.
"""

from __future__ import annotations

import argparse
import csv
import subprocess
import tempfile
from collections import Counter
from pathlib import Path

from bench_live_feed import DENSITY, json_as_tracks, online_as_tracks, score
from cli_run import CLI
from cli_run import echo_run as _run
from cli_run import env as _env


def live_rows(d: Path, release: str, frames: str = "eighth") -> Path:
    """``live --release RELEASE`` (``frames`` ``sector``: ``--sector-frames``) on
    ``d/radar.ast`` as a tracks file."""
    args = ["live", "--stdin", "raw", "--sensors", str(d / "sensors.toml"), "--day-from",
            "stream", "--birth-density", DENSITY, "--json", "--no-preload", "--release",
            release, *(["--sector-frames"] if frames == "sector" else [])]
    print(f"$ mhtrack {' '.join(args)} < {d / 'radar.ast'}", flush=True)
    with (d / "radar.ast").open("rb") as fh:
        out = subprocess.run([*CLI, *args], stdin=fh, capture_output=True, text=True,
                             env=_env(), check=True).stdout
    return json_as_tracks(out, d / f"live_{frames}_{release}.csv")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--scans", type=int, default=None)
    ap.add_argument("--frames", nargs="+", choices=("eighth", "sector"),
                    default=["eighth"])
    a = ap.parse_args()
    d = a.out or Path(tempfile.mkdtemp(prefix="release_order_"))
    d.mkdir(parents=True, exist_ok=True)
    _run(["simulate", "opensky-radars", "--seed", "1", "--out", str(d), "-q",
          *(["--scans", str(a.scans)] if a.scans else [])])
    _run(["export", str(d / "plots.csv"), "--sensors", str(d / "sensors.toml"), "--out",
          str(d / "radar.ast"), "-q"])
    _run(["track", str(d / "radar.ast"), "--sensors", str(d / "sensors.toml"),
          "--output", "online", "--birth-density", DENSITY, "--out",
          str(d / "online.csv"), "-q"])
    runs = {"track --output online": online_as_tracks(d / "online.csv", d / "track.csv")}
    for frames in a.frames:
        if frames == "sector":  # track's rows with the option, beside live's
            _run(["track", str(d / "radar.ast"), "--sensors", str(d / "sensors.toml"),
                  "--output", "online", "--birth-density", DENSITY, "--sector-frames",
                  "--out", str(d / "online_sector.csv"), "-q"])
            runs["track --output online --sector-frames"] = online_as_tracks(
                d / "online_sector.csv", d / "track_sector.csv")
        for release in ("time", "radar"):
            opt = " --sector-frames" if frames == "sector" else ""
            runs[f"live --release {release}{opt}"] = live_rows(d, release, frames)
    rows = {k: _rows(p) for k, p in runs.items()}
    base = rows["live --release time"]
    print("\n| run | rows | rows equal to --release time's (time, id, x, y, vx, vy) | "
          "OSPA (m) | coverage | track ids | id switches |\n|---|---|---|---|---|---|---|")
    for k, p in runs.items():
        s = score(p, d / "truth.csv")
        same = "(other rounding)" if k.startswith("track") else \
            f"{sum((Counter(rows[k]) & Counter(base)).values())}"
        print(f"| {k} | {len(rows[k])} | {same} | {s['ospa_mean']:.2f} | "
              f"{s['coverage']:.4f} | {s['n_track_ids']} | {s['id_switches']} |")


def _rows(path: Path) -> list[tuple[str, ...]]:
    """``(time, track_id, x, y, vx, vy)`` of each row of a tracks file."""
    with path.open(newline="") as fh:
        return [(r["time"], r["track_id"], r["x"], r["y"], r["vx"], r["vy"])
                for r in csv.DictReader(fh)]

if __name__ == "__main__":
    main()
