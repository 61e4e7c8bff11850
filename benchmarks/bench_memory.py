"""Peak RSS of ``mhtrack track`` against the recording's length (issue 33, deliverable 6).

Three rotating radars and 20 targets (``bench_async.hour_scene``, the hour benchmark's
scene) for each of ``--minutes``, written as range/bearing plots with a sensors file
(sites as lat/lon about 46.8° N 8.2° E), exported to a ``.pcap`` ASTERIX recording by
``mhtrack export``, then tracked by ``mhtrack track REC --sensors S --out T.csv|.parquet``
under ``/usr/bin/time -v`` ("Maximum resident set size"). With ``--reference SRC`` the
same commands run with ``PYTHONPATH=SRC`` (e.g. a worktree of an earlier commit), beside
ours in the table; the tracks files of both are compared byte for byte.

Run::

    PYTHONPATH=src python benchmarks/bench_memory.py [--minutes 10 20 40 80] \\
        [--reference /path/to/old/src]
"""

from __future__ import annotations

import argparse
import filecmp
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import tomli_w

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "mht"))

from bench_async import hour_scene  # noqa: E402
from mhtrack.io.sensors import sensors_to_dict  # noqa: E402
from mhtrack.models.geodesy import LocalFrame  # noqa: E402

ORIGIN = (46.8, 8.2)


def recording(minutes: int, d: Path, src: str) -> Path:
    """``d/radar.pcap`` and ``d/sensors.toml``: ``minutes`` of the hour scene."""
    d.mkdir(parents=True, exist_ok=True)
    sim = hour_scene(60.0 * minutes)
    p = sim.plots
    site = {s.id: s.position for s in sim.sensors.sensors}
    sx = np.array([site[int(s)][0] for s in p.sensor])
    sy = np.array([site[int(s)][1] for s in p.sensor])
    rng, brg = np.hypot(p.x - sx, p.y - sy), np.degrees(np.arctan2(p.x - sx, p.y - sy)) % 360
    o = np.argsort(p.time, kind="stable")
    with open(d / "plots.csv", "w") as f:
        f.write("time,sensor,range,bearing\n")
        f.writelines(f"{float(p.time[i])!r},{int(p.sensor[i])},{float(rng[i])!r},"
                     f"{float(brg[i])!r}\n" for i in o)
    sd = sensors_to_dict(sim.sensors)
    sd["origin"] = {"lat": ORIGIN[0], "lon": ORIGIN[1]}
    frame = LocalFrame(*ORIGIN)
    for s in sd["sensors"]:
        lat, lon = frame.to_geodetic(*s.pop("position"))
        s["lat"], s["lon"] = float(lat), float(lon)
    (d / "sensors.toml").write_text(tomli_w.dumps(sd))
    mhtrack(src, ["export", str(d / "plots.csv"), "--sensors", str(d / "sensors.toml"),
                  "--out", str(d / "radar.pcap")])
    return d / "radar.pcap"


def mhtrack(src: str, args: list[str]) -> str:
    """Run ``mhtrack ARGS`` with ``PYTHONPATH=src`` under ``/usr/bin/time -v``; its stderr."""
    env = {**os.environ, "PYTHONPATH": str(Path(src).resolve())}
    cmd = ["/usr/bin/time", "-v", sys.executable, "-c",
           "from mhtrack.cli.main import main; main()", *args]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
    if r.returncode:
        raise SystemExit(f"mhtrack {' '.join(args)} failed:\n{r.stderr[-2000:]}")
    return r.stderr


def peak_mb(src: str, rec: Path, out: Path) -> float:
    """Peak RSS (MB) of ``mhtrack track REC --out OUT``."""
    err = mhtrack(src, ["track", str(rec), "--sensors", str(rec.parent / "sensors.toml"),
                        "--out", str(out), "--quiet"])
    return int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", err)[1]) / 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=int, nargs="+", default=[10, 20, 40, 80])
    ap.add_argument("--reference", help="src folder of the reference (earlier) mhtrack")
    ap.add_argument("--formats", nargs="+", default=["csv", "parquet"])
    a = ap.parse_args()
    ours = str(HERE.parent / "src")
    rows: dict[str, list[tuple[float, float | None]]] = {f: [] for f in a.formats}
    with tempfile.TemporaryDirectory(prefix="bench-memory-") as tmp:
        for m in a.minutes:
            rec = recording(m, Path(tmp) / f"m{m}", ours)
            for fmt in a.formats:
                new = peak_mb(ours, rec, rec.parent / f"ours.{fmt}")
                ref = None
                if a.reference:
                    ref = peak_mb(a.reference, rec, rec.parent / f"ref.{fmt}")
                    if fmt == "csv" and not filecmp.cmp(rec.parent / "ours.csv",
                                                        rec.parent / "ref.csv", shallow=False):
                        print(f"{m} min: tracks.csv differs from the reference's")
                n = None
                if fmt == "csv":
                    n = (rec.parent / "ours.csv").read_bytes().count(b"\n") - 1
                rows[fmt].append((new, ref))
                print(f"{m:3d} min {fmt:8s} ours {new:6.1f} MB"
                      + ("" if ref is None else f"  reference {ref:6.1f} MB")
                      + ("" if n is None else f"  ({n} track rows)"), flush=True)
    print("\n| format | " + " | ".join(f"{m} min" for m in a.minutes) + " | max / min |")
    print("|---|" + "---|" * (len(a.minutes) + 1))
    for fmt, vals in rows.items():
        for who, i in (("ours", 0), ("reference", 1)):
            v = [x[i] for x in vals]
            if None in v:
                continue
            print(f"| {fmt} {who} | " + " | ".join(f"{x:.1f} MB" for x in v)
                  + f" | {max(v) / min(v):.3f} |")


if __name__ == "__main__":
    main()
