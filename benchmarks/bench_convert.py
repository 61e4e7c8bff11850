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
  the reference path, once;
* ``convert`` of a raw stream of the categories libasterix decodes record by record
  (:data:`OTHER_PLOTS` of the hour's plots as CAT001 with their radars' CAT002 north
  markers, and as many CAT021 ADS-B reports): blocks judged by their content, then
  decoded.

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

import numpy as np
from click.testing import CliRunner

#: Plots of the hour encoded as CAT001 (and as many CAT021 reports) for the last case:
#: libasterix's encoder takes a few ms a record, so not the whole hour.
OTHER_PLOTS = 4000


def other_categories(rec: Path, out: Path) -> int:
    """``out``: the first :data:`OTHER_PLOTS` plots of recording ``rec`` as CAT001 plots
    with CAT002 north markers, and as CAT021 reports of one ADS-B station (positions made
    up from range and bearing: only the decoding's cost matters), as raw data blocks.
    Returns the number of records."""
    from mhtrack.io.asterix import read_recording
    from mhtrack.io.asterix.encode_other import blocks, mark002, plot001, report021

    r = read_recording(rec)
    p, sw = r.plots, r.sweeps
    n = min(OTHER_PLOTS, p["time"].size)
    last = float(p["time"][n - 1])
    msgs = [(float(p["time"][i]), int(p["sensor"][i]), 1, plot001(
        float(p["time"][i]), int(p["sensor"][i]), float(p["slant_range"][i]),
        float(p["bearing"][i]))) for i in range(n)]
    north = np.flatnonzero((sw["kind"] == 1) & (sw["time"] <= last))
    msgs += [(float(sw["time"][i]), int(sw["sensor"][i]), 2, mark002(
        float(sw["time"][i]), int(sw["sensor"][i]), 1)) for i in north]
    msgs += [(float(p["time"][i]), 0x0707, 21, report021(
        float(p["time"][i]), 0x0707, 46.0 + float(p["slant_range"][i]) * 1e-6,
        7.0 + float(p["bearing"][i]) * 1e-3, address=f"{i:06x}")) for i in range(n)]
    out.write_bytes(b"".join(b for _, _, b in blocks(msgs)))
    return len(msgs)


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
        other = d / "other.ast"
        n_other = other_categories(rec, other)
        t_other = best_of(lambda: convert(other, d / "out.csv", sensors), args.repeat)
        print(f"{'what':44s} {'s':>7s} {'plots/s':>9s}")
        for what, t in (("convert (decode, ground range, write CSV)", t_conv),
                        ("convert, raw data blocks (.ast)", t_raw),
                        ("decode, fast path", t_fast),
                        ("decode, libasterix record by record", t_slow)):
            print(f"{what:44s} {t:7.2f} {n / t:9.0f}")
        print(f"{'convert, raw CAT001/002/021 (.ast)':44s} {t_other:7.2f} "
              f"{n_other / t_other:9.0f} records/s ({n_other} records)")
        print(f"libasterix {_lib.version()}; target >= 20000 plots/s for convert: "
              f"{'met' if n / t_conv >= 20000 else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
