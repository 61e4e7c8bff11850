"""Issue 30: CAT062 encoding of track rows with attributes, libasterix against NumPy
(:mod:`mhtrack.io.asterix.cat062_attr_octets`), in the same run.

``mhtrack simulate opensky-radars --seed S --out D`` (attributes on: the default), ``mhtrack
track D/plots.csv --sensors D/sensors.toml --out D/tracks.csv``; the tracks file read
back (:func:`mhtrack.io.tracks.read_tracks`, with its attributes) and its rows encoded
by both paths: libasterix (``encode_blocks(table_messages(...))``) and
:func:`~mhtrack.io.asterix.cat062_fast.blocks062`. The data blocks must be equal,
octet for octet (the script stops otherwise); then each encoder is timed ``--repeat``
times (CPU, ``time.process_time``; the best run) and printed per 10 000 rows, with and
without the attributes (the same rows, ``attrs=None``).

Run: ``PYTHONPATH=src python benchmarks/bench_cat062_encode.py [--seed 1] [--repeat 3]
[--dir D]`` (``--dir``: reuse a directory where both commands have run).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import io
import tempfile
import time
from pathlib import Path

from mhtrack.cli.main import cli
from mhtrack.io.asterix.cat062 import table_messages
from mhtrack.io.asterix.cat062_fast import blocks062
from mhtrack.io.asterix.encode import encode_blocks
from mhtrack.io.sensors import read_sensors
from mhtrack.io.tracks import read_tracks


def _cli(args: list[str]) -> None:
    with contextlib.redirect_stdout(io.StringIO()):
        cli.main(args, standalone_mode=False)


def _best(f, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        f()
        best = min(best, time.process_time() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--dir", type=Path, default=None)
    a = ap.parse_args()
    d = a.dir or Path(tempfile.mkdtemp(prefix="cat062enc_"))
    if not (d / "tracks.csv").exists():
        _cli(["simulate", "opensky-radars", "--seed", str(a.seed), "--out", str(d)])
        _cli(["track", str(d / "plots.csv"), "--sensors", str(d / "sensors.toml"),
              "--out", str(d / "tracks.csv")])
    frame = read_sensors(d / "sensors.toml").frame()
    tracks = read_tracks(d / "tracks.csv", frame=frame)
    assert tracks.attrs is not None, "the tracks file has no attribute columns"
    n = len(tracks)
    at = tracks.attrs
    print(f"{d}: {n} track rows; with Mode 3/A {int((at.mode_3a >= 0).sum())}, flight "
          f"level {int((at.flight_level == at.flight_level).sum())}, callsign "
          f"{int((at.callsign != '').sum())}, I062/340 {int((at.meas_sensor >= 0).sum())}")
    for label, rows in (("with attributes", tracks),
                        ("without attributes", dataclasses.replace(tracks, attrs=None))):
        ref = list(encode_blocks(table_messages(rows, frame, "tracks")))
        fast = list(blocks062(rows, frame, "tracks"))
        if fast != ref:
            raise SystemExit(f"{label}: the NumPy blocks differ from libasterix's")
        octets = sum(len(b) for _, _, b in ref)
        t_lib = _best(lambda rows=rows: list(encode_blocks(table_messages(
            rows, frame, "tracks"))), a.repeat)
        t_np = _best(lambda rows=rows: list(blocks062(rows, frame, "tracks")), a.repeat)
        per = 10_000 / n
        print(f"{label}: {len(ref)} data blocks, {octets} octets, equal octet for octet; "
              f"CPU per 10 000 rows: libasterix {t_lib * per:.3f} s, NumPy "
              f"{t_np * per:.4f} s ({t_lib / t_np:.0f}×)")


if __name__ == "__main__":
    main()
