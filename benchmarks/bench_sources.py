"""Peak memory and time per plot of reading an ASTERIX recording as a source
(:func:`mhtrack.sources.open_source`), beside today's path of ``mhtrack track`` measured
in the same run (``read_recording`` → temporary Parquet + sensors file →
``read_plots`` → ``PlotTable.scans``).

Run: ``PYTHONPATH=src python benchmarks/bench_sources.py [--scans 360] [--seed 1]``.
Simulates ``opensky-radars`` (``--scans 360``: an hour of three rotating radars, about
64 000 plots, as ``bench_convert.py``), exports it as a ``.pcap`` (``mhtrack export``),
then runs each path in a fresh process that imports everything first (libasterix, pyproj)
and reports the peak of its resident memory while it reads every frame (``/proc/self/
statm`` sampled every 2 ms by a thread: ``ru_maxrss`` is the import of libasterix's
generated module, ~330 MB, higher than either path) above the memory after the imports,
and the wall time. The source's time includes its survey pass (radars, periods, every plot's
``x, y`` for the surveillance area: a second decode of the file). Wall times are noisy on
a shared machine.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import json, resource, sys, tempfile, time
from pathlib import Path
import numpy as np
from mhtrack.io.asterix import _lib
from mhtrack.io.sensors import read_sensors
from mhtrack.models.geodesy import polar_to_local  # noqa: F401  (pyproj loaded)
from mhtrack.records import Scan
import pyarrow.parquet  # noqa: F401
_lib.modules()
import os, threading
rec, sens, which = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
sensors = read_sensors(sens)
PAGE = os.sysconf("SC_PAGE_SIZE")
def rss():
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * PAGE / 2**20
peak, done = [rss()], threading.Event()
def sample():
    while not done.is_set():
        peak.append(max(peak[-1], rss()))
        time.sleep(0.002)
sampler = threading.Thread(target=sample, daemon=True)
rss0 = rss()
sampler.start()
t0 = time.perf_counter()
n = frames = 0
if which == "today":
    from mhtrack.io.asterix import convert, read_recording, sensors_with_periods
    from mhtrack.io.plots import read_plots
    from mhtrack.io.sensors import write_sensors
    with tempfile.TemporaryDirectory() as tmp:
        r = read_recording(rec)
        s2 = sensors_with_periods(sensors, r)
        convert(rec, Path(tmp) / "plots.parquet", s2, recording=r)
        write_sensors(s2, Path(tmp) / "sensors.toml")
        del r
        table = read_plots(Path(tmp) / "plots.parquet",
                           sensors=read_sensors(Path(tmp) / "sensors.toml"))
        area = (table.x, table.y)
        for scan in table.scans():
            n += len(scan); frames += 1
else:
    from mhtrack.sources import open_source
    src = open_source(rec, sensors=sensors)
    area = src.survey()
    for scan in src:
        n += len(scan); frames += 1
wall = time.perf_counter() - t0
done.set(); sampler.join()
print(json.dumps({"plots": n, "frames": frames, "wall_s": wall, "rss_start_mb": rss0,
                  "rss_peak_mb": max(peak), "ru_maxrss_mb":
                  resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def run(rec: Path, sensors: Path, which: str) -> dict[str, float]:
    """One path in a fresh process: its figures."""
    out = subprocess.run([sys.executable, "-c", CHILD, str(rec), str(sensors), which],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scans", type=int, default=360, help="opensky-radars 10-s scans")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    from click.testing import CliRunner

    from mhtrack.cli.main import cli
    from mhtrack.io.asterix import export
    from mhtrack.io.sensors import read_sensors

    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        r = CliRunner().invoke(cli, ["simulate", "opensky-radars", "--seed", str(args.seed),
                                     "--scans", str(args.scans), "--no-attributes",
                                     "--out", str(d)])
        if r.exit_code != 0:
            print(r.output, file=sys.stderr)
            return 1
        rec = d / "rec.pcap"
        export(d / "plots.csv", read_sensors(d / "sensors.toml"), rec)
        print(f"recording: {rec.stat().st_size / 1e6:.1f} MB, opensky-radars seed "
              f"{args.seed}, {args.scans} scans")
        res = {w: run(rec, d / "sensors.toml", w) for w in ("today", "source")}
    for w, label in (("today", "read_recording + temp Parquet + read_plots"),
                     ("source", "open_source (survey + frames)")):
        f = res[w]
        print(f"{label}: {f['plots']} plots, {f['frames']} frames, {f['wall_s']:.2f} s "
              f"({1e6 * f['wall_s'] / f['plots']:.1f} µs/plot); RSS peak while reading "
              f"{f['rss_peak_mb']:.0f} MB = {f['rss_peak_mb'] - f['rss_start_mb']:.1f} MB "
              f"above the {f['rss_start_mb']:.0f} MB after imports")
    print(json.dumps(res))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
