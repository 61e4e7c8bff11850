"""Soak of ``mhtrack live`` (issue 30, *Bounded for days*): hours of replayed traffic at
``--speed max`` over loopback UDP, the RSS of the ``live`` process sampled at every hour
of data time (``docs/live.md``, *Soak*).

    python benchmarks/soak.py [--hours 6] [--out DIR] [--chunk-s 1200]

Traffic: ``mhtrack simulate opensky-radars --seed 1 --no-attributes`` (3 radars, 1 200 s, about 30
plots/s), its plots played again and again with the time running on — pass ``k`` is the
same plots ``k · 1200 s`` later — from 23:30 UTC, so the data cross midnight once (the
time of day wraps at 24:00; the tracker's axis goes on); each pass exported
(``mhtrack export``) as one pcap. The aircraft jump back to their first positions at
each pass: every track of a pass ends and new ones are born, which is what a soak
must survive (finished tracks leaving memory).

One ``mhtrack live --listen udp://127.0.0.1:0 --day-from stream --birth-density 1e-10
--checkpoint … --checkpoint-every 10`` runs throughout; each pass is sent by ``mhtrack
replay PASS.pcap --speed max`` once ``live`` has taken the last one (its status JSON:
datagrams received, plots decoded and frames tracked unchanged for five status
periods) — so the RSS is the tracker's, not a backlog in the queue. After
each hour's passes: ``VmRSS`` and ``VmHWM`` of ``/proc/PID/status``. Prints one row per
hour and the ratio hour N / hour 1.
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from cli_run import CLI
from cli_run import env as _env
from cli_run import run as _run

#: The first pass starts at 23:30 UTC: the data cross midnight after 30 min.
START_S = 84_600.0
#: Longest wait (wall s) for ``live`` to take one pass.
PASS_TIMEOUT_S = 1800.0
#: A pass is taken once the status stood still this many status periods (1 s).
STILL_S = 5


def passes(d: Path, n: int, chunk_s: float) -> list[Path]:
    """``n`` pcaps: the simulated plots shifted by ``START_S + k · chunk_s``."""
    sim = d / "sim"
    if not (sim / "plots.csv").exists():
        _run(["simulate", "opensky-radars", "--seed", "1", "--no-attributes", "--out", str(sim),
              "-q"])
    with (sim / "plots.csv").open() as fh:
        rows = list(csv.reader(fh))
    head, body = rows[0], rows[1:]
    ti = head.index("time")
    out = []
    for k in range(n):
        pcap = d / f"pass{k:03d}.pcap"
        if not pcap.exists():
            shifted = d / "pass.csv"
            with shifted.open("w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(head)
                for r in body:
                    r = list(r)
                    r[ti] = repr(float(r[ti]) + START_S + k * chunk_s)
                    w.writerow(r)
            _run(["export", str(shifted), "--sensors", str(sim / "sensors.toml"),
                  "--out", str(pcap), "-q"])
        out.append(pcap)
    return out


def rss_kb(pid: int) -> tuple[int, int]:
    """``VmRSS`` and ``VmHWM`` (kB) of process ``pid``."""
    got = {}
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        key, _, value = line.partition(":")
        if key in ("VmRSS", "VmHWM"):
            got[key] = int(value.split()[0])
    return got["VmRSS"], got["VmHWM"]


def _status(path: Path) -> dict:
    for _ in range(50):
        try:
            return json.loads(path.read_text())
        except (FileNotFoundError, json.JSONDecodeError):
            time.sleep(0.1)
    raise RuntimeError(f"no status in {path}")


def wait_taken(status: Path, before: int, live: subprocess.Popen) -> dict:
    """The status once ``live`` has taken a pass: datagrams received beyond ``before``,
    and datagrams, plots and frames unchanged over :data:`STILL_S` status periods (the
    kernel's drops of a pass show only with the next datagram, so they cannot close the
    count)."""
    t0, last, still = time.monotonic(), None, 0
    while time.monotonic() - t0 < PASS_TIMEOUT_S:
        if live.poll() is not None:
            raise RuntimeError(f"live ended (exit {live.returncode})")
        time.sleep(1.0)
        s = _status(status)
        key = (s["datagrams"], s["plots"], s["frames"])
        still = still + 1 if key == last and s["datagrams"] > before else 0
        if still >= STILL_S:
            return s
        last = key
    raise RuntimeError(f"live did not take the pass within {PASS_TIMEOUT_S} s")


def probe(d: Path, tag: str, live: subprocess.Popen) -> dict:
    """Ask ``memprobe.py`` in ``live`` for ``probe-TAG.json`` and wait for it."""
    (d / f"req-{tag}").touch()
    for _ in range(6000):  # bounded: 10 min
        out = d / f"probe-{tag}.json"
        if out.exists():
            return json.loads(out.read_text())
        if live.poll() is not None:
            raise RuntimeError(f"live ended (exit {live.returncode})")
        time.sleep(0.1)
    raise RuntimeError(f"no probe {tag}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=int, default=6)
    ap.add_argument("--chunk-s", type=float, default=1200.0,
                    help="data seconds of one pass (the simulation's length)")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--probe", type=int, default=None, metavar="FRAMES",
                    help="run live under benchmarks/memprobe.py (tracemalloc with FRAMES "
                         "frames, 0: off) and probe its memory before the first pass "
                         "(probe-p0.json), after each pass (probe-pK.json) and at each "
                         "hour, then malloc_trim (probe-hN-trim.json)")
    a = ap.parse_args()
    d = a.out or Path(tempfile.mkdtemp(prefix="soak_"))
    d.mkdir(parents=True, exist_ok=True)
    per_hour = round(3600.0 / a.chunk_s)
    t_prep = time.monotonic()
    pcaps = passes(d, per_hour * a.hours, a.chunk_s)
    print(f"{len(pcaps)} passes of {a.chunk_s:.0f} s in {d} "
          f"({time.monotonic() - t_prep:.0f} s to prepare)", flush=True)
    status = d / "status.json"
    live_args = ["live", "--listen", "udp://127.0.0.1:0", "--sensors",
                 str(d / "sim" / "sensors.toml"), "--day-from", "stream",
                 "--birth-density", "1e-10", "--status-json", str(status),
                 "--status-every", "1", "--checkpoint", str(d / "state.npz"),
                 "--checkpoint-every", "10", "-q"]
    print("$ mhtrack " + " ".join(live_args), flush=True)
    err_path = d / "live.err"  # a file, not a pipe: a status line a second would fill one
    cmd = [*CLI, *live_args]
    if a.probe is not None:
        cmd = [sys.executable, str(Path(__file__).with_name("memprobe.py")), "--dir",
               str(d / "probes"), "--trace", str(a.probe), "--", *live_args]
    with err_path.open("w") as err_file:
        live = subprocess.Popen(cmd, stderr=err_file,
                                stdout=subprocess.DEVNULL, text=True, env=_env())
    rows = []
    try:
        m = None
        for _ in range(600):  # bounded: the first line names the port
            first = err_path.read_text().split("\n", 1)[0].strip()
            m = re.match(r"listening on (udp://127\.0\.0\.1:\d+)$", first)
            if m is not None or live.poll() is not None:
                break
            time.sleep(0.5)
        if m is None:
            raise RuntimeError(f"live did not start: {err_path.read_text()!r}")
        to, sent, t0, got = m.group(1), 0, time.monotonic(), 0
        if a.probe is not None:
            probe(d / "probes", "p0", live)
        print("$ mhtrack replay PASS.pcap --to " + to + " --speed max  (each pass)")
        print("| data hour | wall s | datagrams sent | received | kernel drops | plots | "
              "frames | tracks | RSS MB | peak RSS MB |", flush=True)
        print("|---|---|---|---|---|---|---|---|---|---|", flush=True)
        for k, pcap in enumerate(pcaps):
            said = _run(["replay", str(pcap), "--to", to, "--speed", "max"])
            sent += int(re.search(r"sent (\d+) datagrams", said).group(1))
            s = wait_taken(status, got, live)
            got = s["datagrams"]
            if (k + 1) % per_hour == 0:
                rss, hwm = rss_kb(live.pid)
                row = ((k + 1) // per_hour, time.monotonic() - t0, sent, s["datagrams"],
                       s.get("kernel_drops"), s["plots"], s["frames"], s["tracks"],
                       rss / 1024, hwm / 1024)
                rows.append(row)
                print("| {} | {:.0f} | {} | {} | {} | {} | {} | {} | {:.1f} | {:.1f} |"
                      .format(*row), flush=True)
                if a.probe is not None:
                    probe(d / "probes", f"h{row[0]}-trim", live)
            elif a.probe is not None:
                probe(d / "probes", f"p{k + 1}", live)
        live.send_signal(signal.SIGTERM)
        live.wait(timeout=600)
        err = err_path.read_text().strip().splitlines()
        print(err[-1] if err else "", flush=True)
    finally:
        if live.poll() is None:
            live.kill()
    if len(rows) >= 2:
        print(f"RSS hour {rows[-1][0]} / hour {rows[0][0]}: {rows[-1][8] / rows[0][8]:.3f}")


if __name__ == "__main__":
    main()
