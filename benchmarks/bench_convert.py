"""Speed of ``mhtrack convert``: ASTERIX CAT048/CAT034 recordings decoded to a plots table.

Run: ``PYTHONPATH=src python benchmarks/bench_convert.py [--seed 1] [--repeat 3]``.
Simulates an hour of ``opensky-radars`` (``--scans 360``: three rotating radars, about
64 000 plots with clutter), exports it as a ``.pcap`` of CAT048 reports and CAT034 north
markers / sector crossings (``mhtrack export``), then times, best of ``--repeat``:

* ``convert`` — read, decode, ground range (with the sensors file), write the CSV, as
  ``mhtrack convert REC OUT --sensors FILE`` does (target ≥ 20 000 plots/s);
* ``convert`` of the same data blocks written back to back as a raw stream (``.ast``:
  blocks judged by their content too, :mod:`mhtrack.io.asterix.resync`);
* decoding alone through :mod:`mhtrack.io.asterix.fast` (layouts learnt from libasterix);
* decoding alone through libasterix record by record (``read_recording(fast=False)``),
  the reference path, once.

libasterix is imported before the clocks start (its generated module takes ~1 s to
import). Timings are wall time on a shared machine: noisy.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from click.testing import CliRunner


def best_of(f: Callable[[], object], repeat: int) -> float:
    """Fastest of ``repeat`` wall times (s)."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    from mhtrack.cli.main import cli
    from mhtrack.io.asterix import _lib, convert, export, read_recording
    from mhtrack.io.asterix.framings import units
    from mhtrack.io.asterix.problems import Problems
    from mhtrack.io.sensors import read_sensors

    _lib.modules()
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        r = CliRunner().invoke(cli, ["simulate", "opensky-radars", "--seed", str(args.seed),
                                     "--scans", "360", "--no-attributes", "--out", str(d)])
        if r.exit_code != 0:
            print(r.output, file=sys.stderr)
            return 1
        sensors = read_sensors(d / "sensors.toml")
        rec = d / "hour.pcap"
        t0 = time.perf_counter()
        n, blocks = export(d / "plots.csv", sensors, rec)
        t_export = time.perf_counter() - t0
        print(f"opensky-radars --seed {args.seed} --scans 360: {n} plots, exported as "
              f"{blocks} data blocks ({rec.stat().st_size / 1e6:.1f} MB pcap) in "
              f"{t_export:.1f} s ({n / t_export:.0f} plots/s)")
        t_conv = best_of(lambda: convert(rec, d / "out.csv", sensors), args.repeat)
        raw = d / "hour.ast"  # the same data blocks back to back, no framing of their own
        raw.write_bytes(b"".join(p for _, _, p in units(
            rec.read_bytes(), "pcap", "hour.pcap", {34, 48}, Problems())))
        t_raw = best_of(lambda: convert(raw, d / "out.csv", sensors), args.repeat)
        t_fast = best_of(lambda: read_recording(rec), args.repeat)
        t_slow = best_of(lambda: read_recording(rec, fast=False), 1)
        print(f"{'what':44s} {'s':>7s} {'plots/s':>9s}")
        for what, t in (("convert (decode, ground range, write CSV)", t_conv),
                        ("convert, raw data blocks (.ast)", t_raw),
                        ("decode, fast path", t_fast),
                        ("decode, libasterix record by record", t_slow)):
            print(f"{what:44s} {t:7.2f} {n / t:9.0f}")
        print(f"libasterix {_lib.version()}; target >= 20000 plots/s for convert: "
              f"{'met' if n / t_conv >= 20000 else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
