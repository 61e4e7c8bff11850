"""Damaged-feed acceptance of issue 30 (``docs/live.md``, *A damaged feed*): the
``opensky-radars`` recording (seed 1) replayed on two redundant LANs — every datagram sent
to two ports ``live`` listens on — with a share of the copies dropped and a share delayed
(seeded, ``mhtrack replay --drop P --delay P:SECONDS --seed N``), into ``mhtrack live``;
its tracks scored against the truth (OSPA, coverage, track ids) beside ``mhtrack track
--output online`` on the clean recording, scored the same way in the same run.

    python benchmarks/bench_live_feed.py [--speed 10 --speed max] [--scans N] [--out DIR]

Both outputs go through one conversion to a tracks file (``frame, time, track_id, x, y,
vx, vy, plot, tentative``: local velocity, ``plot`` 0 on an update and empty on a miss)
and ``mhtrack evaluate --json``. Prints one table row per speed, with the command lines.
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import signal
import subprocess
import tempfile
from pathlib import Path

from cli_run import CLI
from cli_run import echo_run as _run
from cli_run import env as _env

DENSITY = "1e-10"
FIELDS = ("frame", "time", "track_id", "x", "y", "vx", "vy", "plot", "tentative")


def _write(rows: list[tuple], path: Path) -> Path:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(FIELDS)
        w.writerows(rows)
    return path


def online_as_tracks(online_csv: Path, out: Path) -> Path:
    """``track --output online``'s file in the common form (module docstring)."""
    rows = []
    with online_csv.open() as fh:
        for r in csv.DictReader(fh):
            rows.append((r["frame"], r["time"], r["track_id"], r["x"], r["y"],
                         r["vx_grid"], r["vy_grid"], "0" if r["plot"] else "",
                         r.get("tentative") or "0"))
    return _write(rows, out)


def json_as_tracks(lines: str, out: Path) -> Path:
    """``live --json``'s lines in the common form (module docstring)."""
    rows = []
    for line in lines.splitlines():
        r = json.loads(line)
        rows.append((r["frame"], r["time"], r["track_id"], r["x"], r["y"], r["vx"],
                     r["vy"], "" if r["coasting"] else "0", int(r["tentative"])))
    return _write(rows, out)


def score(tracks: Path, truth: Path) -> dict[str, float]:
    """OSPA, coverage and track ids of ``tracks`` (``mhtrack evaluate --json``)."""
    e = json.loads(_run(["evaluate", str(tracks), str(truth), "--json", "-q"]))
    return {k: e[k] for k in ("ospa_mean", "coverage", "n_track_ids", "id_switches",
                              "n_matches")}


def live_run(d: Path, speed: str, drop: float, delay: float, delay_s: float,
             seed: int) -> tuple[Path, dict[str, int], str]:
    """Replay ``d/radar.pcap`` to two ports of one ``live``; its tracks file, counts
    (replay's and live's) and the two command lines."""
    live_args = ["live", "--listen", "udp://127.0.0.1:0", "--listen", "udp://127.0.0.1:0",
                 "--sensors", str(d / "sensors.toml"), "--day-from", "stream",
                 "--birth-density", DENSITY, "--json", "--status-json",
                 str(d / f"status_{speed}.json")]
    print("$ mhtrack " + " ".join(live_args), flush=True)
    live = subprocess.Popen([*CLI, *live_args], stderr=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, env=_env())
    try:
        first = live.stderr.readline().strip()
        ports = re.findall(r"udp://127\.0\.0\.1:\d+", first)
        if not first.startswith("listening on") or len(ports) != 2:
            raise RuntimeError(f"live did not start: {first!r}")
        rep = ["replay", str(d / "radar.pcap"), "--to", ports[0], "--to", ports[1],
               "--speed", speed, "--drop", str(drop), "--delay", f"{delay}:{delay_s}",
               "--seed", str(seed)]
        said = _run(rep)
        live.send_signal(signal.SIGTERM)
        out, err = live.communicate()
    finally:
        if live.poll() is None:
            live.kill()
    if live.returncode != 0:
        raise RuntimeError(err)
    sent = re.search(r"sent (\d+) datagrams.*; (\d+) copies dropped, (\d+) delayed", said)
    st = json.loads((d / f"status_{speed}.json").read_text())
    counts = {"sent": int(sent.group(1)), "dropped": int(sent.group(2)),
              "delayed": int(sent.group(3)), "received": st["datagrams"],
              "queue_drops": st["queue_drops"], "duplicates": st["duplicates"],
              "late_drops": st["late_drops"]}
    return json_as_tracks(out, d / f"live_{speed}.csv"), counts, " | ".join(
        ["mhtrack " + " ".join(live_args), "mhtrack " + " ".join(rep)])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speed", action="append", default=None)
    ap.add_argument("--scans", type=int, default=None, help="simulate fewer scans")
    ap.add_argument("--drop", type=float, default=0.01)
    ap.add_argument("--delay", type=float, default=0.01)
    ap.add_argument("--delay-s", type=float, default=3.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    d = a.out or Path(tempfile.mkdtemp(prefix="bench_live_feed_"))
    d.mkdir(parents=True, exist_ok=True)
    _run(["simulate", "opensky-radars", "--seed", "1", "--no-attributes", "--out", str(d), "-q",
          *(["--scans", str(a.scans)] if a.scans else [])])
    _run(["export", str(d / "plots.csv"), "--sensors", str(d / "sensors.toml"), "--out",
          str(d / "radar.pcap"), "-q"])
    _run(["track", str(d / "radar.pcap"), "--sensors", str(d / "sensors.toml"),
          "--output", "online", "--birth-density", DENSITY, "--out",
          str(d / "online.csv"), "-q"])
    truth = d / "truth.csv"
    ref = score(online_as_tracks(d / "online.csv", d / "clean.csv"), truth)
    rows = []
    for speed in a.speed or ["10"]:
        tracks, counts, cmd = live_run(d, speed, a.drop, a.delay, a.delay_s, a.seed)
        rows.append((speed, score(tracks, truth), counts, cmd))
    print(f"\nclean: track --output online on {d / 'radar.pcap'}: OSPA "
          f"{ref['ospa_mean']:.2f} m, coverage {ref['coverage']:.4f}, "
          f"{ref['n_track_ids']} track ids, {ref['id_switches']} id switches")
    print("| speed | OSPA (m) | ΔOSPA | coverage | Δcov | track ids | id switches | "
          "copies sent / dropped / delayed | received | duplicates | late drops |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for speed, s, c, _ in rows:
        print(f"| {speed} | {s['ospa_mean']:.2f} | "
              f"{100 * (s['ospa_mean'] / ref['ospa_mean'] - 1):+.2f} % | "
              f"{s['coverage']:.4f} | {100 * (s['coverage'] / ref['coverage'] - 1):+.2f} % "
              f"| {s['n_track_ids']} ({ref['n_track_ids']}) | {s['id_switches']} "
              f"({ref['id_switches']}) | {c['sent']} / {c['dropped']} / {c['delayed']} | "
              f"{c['received']} (queue drops {c['queue_drops']}) | {c['duplicates']} | "
              f"{c['late_drops']} |")
    for speed, _, _, cmd in rows:
        print(f"speed {speed}: {cmd}")


if __name__ == "__main__":
    main()
