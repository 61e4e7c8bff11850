"""A national network's load (issue 30, item 5): 30 rotating radars (4–12 s), about
2 000 plots/s and 4 000 aircraft, replayed at real time into ``mhtrack live``.

    python benchmarks/national.py [--out DIR] [--duration 600] [--skip-live]
        [--profile-s 60] [--stonesoup-s 60] [--box-km 150]

Stages (each prints its command or what it does, and how long it took):

1. **Scene** — :func:`mhtrack.scenario.network.network_scenario` (radars on a jittered
   grid over 1 200 × 1 000 km, periods 4–12 s, reach 180–250 km, aircraft at cruise or
   terminal speeds) simulated with ``--seed``; written as ``mhtrack simulate`` writes it
   (plots, truth, sensors file, scenario), then ``mhtrack export`` to ``radar.pcap``
   (CAT048 plots, CAT034 sectors). Kept in DIR: a second run with the same arguments
   reuses it.
2. **Live** — ``mhtrack live`` on a loopback port, CAT062 out to a loopback socket this
   script drains and counts, ``--status-every 10`` and ``--status-json``; fed by
   ``mhtrack replay radar.pcap --speed 1`` (real time). ``live``'s RSS is sampled from
   ``/proc`` every second. Once ``replay`` is done, ``live`` gets SIGTERM after 3 s; a
   ``live`` still busy ``--stop-timeout`` seconds later is killed (it fell behind; its
   last status file gives its figures). Printed: plots/s sustained (plots decoded over
   the replay's wall time, and frames tracked), the latency p50/p99 of the whole run and
   of each 10 s status line (a latency that grows line after line is a tracker falling
   behind), RSS (peak and last).
3. **Profile** (``national_profile.py``) — ``cProfile`` of the same pipeline
   (``Pipeline.open(radar.pcap)``, same options) on the recording's first ``--profile-s``
   seconds at full speed: plots per wall- and CPU-second (the capacity of one core) and
   where the time goes, per stage, in CPU seconds (the profiler's timer is the process's CPU
   time: the machine is shared) (``--no-cprofile``: timed without the profiler).
4. **Stone Soup** — its GNN (``benchmarks/stonesoup_timed.py``, as in ``bench_async.py``)
   and mhtrack on a slice of the same scene: the plots within a ``--box-km`` square about
   the centre over the first ``--stonesoup-s`` seconds; plots/s of each.

Loopback only (127.0.0.1); every wait is bounded.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import pickle
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from cli_run import CLI
from cli_run import echo_run as _run
from cli_run import env as _env

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


# ------------------------------------------------------------------ 1. scene
def scene(a: argparse.Namespace, d: Path) -> dict:
    """Simulate, write and export the scene into ``d`` (reused when ``d/meta.json`` has
    the same arguments); the scene's figures."""
    from mhtrack.build.radar_defaults import radar_rule
    from mhtrack.io import write_plots, write_scenario_toml, write_truth
    from mhtrack.io.sensors import write_sensors
    from mhtrack.mht import MHTConfig
    from mhtrack.scenario import simulate
    from mhtrack.scenario.network import network_scenario

    key = {k: getattr(a, k) for k in ("radars", "aircraft", "duration", "clutter_per_s",
                                      "seed", "scene_seed", "box_km", "stonesoup_s")}
    meta_path = d / "meta.json"
    if meta_path.is_file() and (d / "radar.pcap").is_file():
        meta = json.loads(meta_path.read_text())
        if meta["key"] == key:
            print(f"scene: reusing {d}")
            return meta
    t0 = time.perf_counter()
    sc = network_scenario(n_radars=a.radars, n_aircraft=a.aircraft, duration_s=a.duration,
                          clutter_per_s=a.clutter_per_s, seed=a.scene_seed)
    sim = simulate(sc, seed=a.seed)
    t_sim = time.perf_counter() - t0
    p, sset = sim.plots, sc.sensor_set()
    write_plots(p, d / "plots.csv")
    write_truth(sim.truth, d / "truth.csv", sset.frame())
    write_sensors(sset, d / "sensors.toml")
    write_scenario_toml({"seed": a.seed, **sc.to_dict()}, d / "scenario.toml")
    rule = radar_rule(sset, p.sensor, p.time, p.x, p.y, v_max=MHTConfig().v_max)
    # the Stone Soup slice: plots in a box about the centre, first seconds
    h = 500.0 * a.box_km
    box = (np.abs(p.x) <= h) & (np.abs(p.y) <= h) & (p.time < p.time.min() + a.stonesoup_s)
    scans = [s for s in (_take(s, box[s.rows]) for s in p.scans()) if len(s.rows)]
    with (d / "slice.pkl").open("wb") as fh:
        pickle.dump({"scans": scans, "pd": {s.id: float(q) for s, q in
                                            zip(sc.sensors, sc.pd, strict=True)},
                     "kappa": {s.id: s.clutter_rate / (math.pi * s.max_range**2)
                               for s in sc.sensors}}, fh)
    t1 = time.perf_counter()
    _run(["export", str(d / "plots.csv"), "--sensors", str(d / "sensors.toml"), "--out",
          str(d / "radar.pcap"), "-q"])
    span = float(p.time.max() - p.time.min())
    seen = np.unique(p.origin[p.origin >= 0]).size
    meta = {"key": key, "plots": len(p), "span_s": span, "plots_per_s": len(p) / span,
            "clutter_share": float((p.origin < 0).mean()), "aircraft_seen": int(seen),
            "frames": int(p.n_scans), "birth_density": rule.new_target_density,
            "periods": sorted(float(s.period) for s in sc.sensors),
            "simulate_s": t_sim, "export_s": time.perf_counter() - t1,
            "pcap_bytes": (d / "radar.pcap").stat().st_size}
    meta_path.write_text(json.dumps(meta, indent=1))
    return meta


def _take(s, keep: np.ndarray):
    """Scan ``s`` with only the plots of mask ``keep``."""
    import dataclasses

    return dataclasses.replace(
        s, z=s.z[keep], sensor=s.sensor[keep], rows=s.rows[keep],
        R=None if s.R is None else s.R[keep], origin=None if s.origin is None else
        s.origin[keep], t=None if s.t is None else s.t[keep])


def live_options(d: Path, meta: dict, a: argparse.Namespace) -> list[str]:
    """The tracker options ``live`` and the profile share."""
    return ["--sensors", str(d / "sensors.toml"), "--birth-density",
            f"{meta['birth_density']:.6g}", "--reorder-window", str(a.reorder_window),
            *(["--release", a.release] if getattr(a, "release", "time") != "time" else []),
            *(["--sector-frames"] if a.frames == "sector" else [])]


# ------------------------------------------------------------------ 2. live
class Drain(threading.Thread):
    """Counts the CAT062 datagrams ``live`` sends to a loopback socket."""

    def __init__(self) -> None:
        super().__init__(daemon=True)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.5)
        self.port, self.count, self.bytes, self.stop = self.sock.getsockname()[1], 0, 0, False

    def run(self) -> None:
        while not self.stop:
            try:
                n = len(self.sock.recv(65536))
            except TimeoutError:
                continue
            self.count, self.bytes = self.count + 1, self.bytes + n


def rss_mb(pid: int) -> tuple[float, float]:
    """``(VmRSS, VmHWM)`` of process ``pid`` in MB (0 when gone)."""
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0.0, 0.0
    get = {m.group(1): int(m.group(2)) / 1024 for m in
           re.finditer(r"^(VmRSS|VmHWM):\s+(\d+) kB", text, re.M)}
    return get.get("VmRSS", 0.0), get.get("VmHWM", 0.0)


def cpu_s(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` (``/proc/PID/stat``; 0 when gone)."""
    try:
        f = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(f[11]) + int(f[12])) / os.sysconf("SC_CLK_TCK")


def live_run(d: Path, meta: dict, a: argparse.Namespace) -> dict:
    """Replay ``d/radar.pcap`` at real time into ``live`` (module docstring, stage 2)."""
    drain = Drain()
    drain.start()
    args = ["live", "--listen", "udp://127.0.0.1:0", *live_options(d, meta, a),
            "--day-from", "stream", "--out-udp", f"udp://127.0.0.1:{drain.port}",
            "--status-every", "10", "--status-json", str(d / "status.json")]
    print("$ mhtrack " + " ".join(args), flush=True)
    live = subprocess.Popen([*CLI, *args], stderr=subprocess.PIPE, stdout=subprocess.DEVNULL,
                            text=True, env=_env())
    lines: list[tuple[float, str]] = []
    rss: list[tuple[float, float]] = []
    try:
        first = live.stderr.readline().strip()
        port = re.findall(r"udp://127\.0\.0\.1:\d+", first)
        if not first.startswith("listening on") or not port:
            raise RuntimeError(f"live did not start: {first!r}")
        t0 = time.time()
        reader = threading.Thread(target=lambda: [lines.append((time.time() - t0, ln.strip()))
                                                  for ln in live.stderr], daemon=True)
        reader.start()
        done = threading.Event()

        def sample() -> None:
            while not done.wait(1.0):
                rss.append((time.time() - t0, rss_mb(live.pid)[0]))
        sampler = threading.Thread(target=sample, daemon=True)
        sampler.start()
        rec = d / "radar.pcap" if a.live_s is None else first_seconds(d, a.live_s)
        rep = ["replay", str(rec), "--to", port[0], "--speed", "1"]
        said = _run(rep)
        t_replay = time.time() - t0
        time.sleep(3.0)
        hwm = rss_mb(live.pid)[1]
        cpu = cpu_s(live.pid)
        with (d / "status.json").open() as fh:
            at_end = json.load(fh)  # the last status before the stop
        t_stop = time.time()
        live.send_signal(signal.SIGTERM)
        killed = False
        try:
            live.wait(timeout=a.stop_timeout)
        except subprocess.TimeoutExpired:  # far behind: the figures of its last status
            live.kill()
            killed = True
        t_exit = time.time() - t_stop
        done.set()
        reader.join(timeout=5)
    finally:
        if live.poll() is None:
            live.kill()
        drain.stop = True
    st = json.loads((d / "status.json").read_text())
    per_line = [(t, float(m.group(1)), float(m.group(2))) for t, ln in lines
                if (m := re.search(r"latency p50 (\d+) ms p99 (\d+) ms", ln))]
    return {"command": "mhtrack " + " ".join(args) + " | mhtrack " + " ".join(rep),
            "replay": said.strip(), "replay_s": t_replay, "stop_s": t_exit, "status": st,
            "killed": killed, "cpu_s": cpu, "at_end": at_end,
            "lines": per_line, "rss_peak_mb": max(hwm, max((r for _, r in rss), default=0)),
            "rss": rss, "cat062_datagrams": drain.count, "last_lines": [ln for _, ln in
                                                                       lines[-3:]]}


def first_seconds(d: Path, seconds: float) -> Path:
    """``d/radar_first{S}s.pcap``: the recording's packets of its first ``seconds`` of
    capture time (pcap: a 24-octet file header, then per packet a 16-octet header —
    seconds, microseconds, captured length, length — and its octets)."""
    out = d / f"radar_first{seconds:g}s.pcap"
    if out.is_file():
        return out
    data = (d / "radar.pcap").read_bytes()
    magic = data[:4]
    end = "<" if magic in (bytes.fromhex("d4c3b2a1"), bytes.fromhex("4d3cb2a1")) else ">"
    frac = 1e-9 if magic in (bytes.fromhex("4d3cb2a1"), bytes.fromhex("a1b23c4d")) else 1e-6
    at, t0 = 24, None
    while at + 16 <= len(data):
        sec, usec, n, _ = np.frombuffer(data, np.dtype(f"{end}u4"), 4, at)
        t = float(sec) + frac * float(usec)
        t0 = t if t0 is None else t0
        if t - t0 > seconds:
            break
        at += 16 + int(n)
    out.write_bytes(data[:at])
    return out


# ------------------------------------------------------------------ 4. Stone Soup
def stonesoup(d: Path, a: argparse.Namespace) -> dict:
    """Stone Soup's GNN and mhtrack on the slice (module docstring, stage 4)."""
    from mhtrack.build import default_config, make_tracker, plots_area
    from mhtrack.experiments.pipeline import track
    from mhtrack.io.sensors import read_sensors
    from mhtrack.records import PlotTable
    from stonesoup_timed import run_stonesoup_timed

    with (d / "slice.pkl").open("rb") as fh:
        sl = pickle.load(fh)
    plots = PlotTable.from_scans(sl["scans"])
    sensors = read_sensors(d / "sensors.toml")
    used = set(np.unique(plots.sensor).tolist())
    cfg = default_config(area=plots_area(plots.x, plots.y).area)
    trk = make_tracker("mht-agmm", cfg, sensors=sensors)
    t0 = time.perf_counter()
    run = track(trk, plots, name="mht-agmm", output="online")
    ours = time.perf_counter() - t0
    res = {"plots": len(plots), "frames": int(plots.n_scans), "radars": len(used),
           "mhtrack_s": ours, "mhtrack_tracks": int(np.unique(run.tracks.track_id).size)}
    if not a.skip_stonesoup:
        r = run_stonesoup_timed(plots, pd={s: sl["pd"][s] for s in used},
                                clutter_density={s: sl["kappa"][s] for s in used}, kind="gnn")
        res.update(stonesoup_s=r.wall,
                   stonesoup_tracks=int(np.unique(r.online.track_id).size))
    return res


# ------------------------------------------------------------------ report
def _pct(v: list[float], q: float) -> float:
    return float(np.percentile(v, q)) if v else float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--radars", type=int, default=30)
    ap.add_argument("--aircraft", type=int, default=4000)
    ap.add_argument("--duration", type=int, default=600, help="seconds of data")
    ap.add_argument("--clutter-per-s", type=float, default=18.0,
                    help="clutter plots per second per radar")
    ap.add_argument("--seed", type=int, default=1, help="simulation seed")
    ap.add_argument("--scene-seed", type=int, default=0)
    ap.add_argument("--reorder-window", type=float, default=0.2)
    ap.add_argument("--frames", choices=("eighth", "sector"), default="eighth",
                    help="live's framing: eighths of a turn (default) or --sector-frames "
                    "(closed at the radar's CAT034 crossings; docs/live.md)")
    ap.add_argument("--release", choices=("time", "radar"), default="time",
                    help="live's --release (docs/live.md, Latency)")
    ap.add_argument("--live-s", type=float, default=None,
                    help="replay only the recording's first seconds into live")
    ap.add_argument("--stop-timeout", type=float, default=300.0,
                    help="seconds live may take to finish after SIGTERM (then killed: a "
                    "tracker that fell behind; its last status counts)")
    ap.add_argument("--profile-s", type=float, default=60.0)
    ap.add_argument("--stonesoup-s", type=float, default=60.0)
    ap.add_argument("--box-km", type=float, default=150.0)
    ap.add_argument("--skip-live", action="store_true")
    ap.add_argument("--skip-profile", action="store_true")
    ap.add_argument("--no-cprofile", action="store_true",
                    help="time the pipeline on --profile-s seconds without the profiler")
    ap.add_argument("--skip-stonesoup", action="store_true")
    a = ap.parse_args()
    d = a.out or Path(tempfile.mkdtemp(prefix="national_"))
    d.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    meta = scene(a, d)
    print(f"scene ({time.perf_counter() - t0:.0f} s): {a.radars} radars (periods "
          f"{min(meta['periods']):g}-{max(meta['periods']):g} s), {a.aircraft} aircraft "
          f"({meta['aircraft_seen']} seen), {meta['span_s']:.0f} s of data, {meta['plots']} "
          f"plots = {meta['plots_per_s']:.0f} plots/s ({100 * meta['clutter_share']:.0f} % "
          f"clutter), {meta['frames']} frames, recording {meta['pcap_bytes'] / 1e6:.0f} MB; "
          f"birth density {meta['birth_density']:.4g} (track's radar rule); simulate "
          f"{meta['simulate_s']:.0f} s, export {meta['export_s']:.0f} s", flush=True)
    if not a.skip_live:
        r = live_run(d, meta, a)
        st, lat = r["status"], r["status"]["latency_s"]
        lines = r["lines"]
        how = "killed after" if r["killed"] else "stop took"
        print(f"\nlive, real time ({r['replay_s']:.0f} s of replay; SIGTERM 3 s later, {how} "
              f"{r['stop_s']:.1f} s): {r['replay']}")
        print(f"  {st['datagrams']} datagrams, {st['plots']} plots decoded = "
              f"{st['plots'] / r['replay_s']:.0f} plots/s sustained over the replay; "
              f"{st['frames']} of the recording's {meta['frames']} frames tracked "
              f"({lat['count']} timed, {lat['after_end']} made "
              f"by the stop); {st['queue_drops']} queue drops, {st['late_drops']} late drops "
              f"({st.get('late_crossings', 0)} late crossings); "
              f"{r['cat062_datagrams']} CAT062 datagrams out; {st['tracks']} tracks at the end")
        old = lat.get("last_plot") or {}
        if lat.get("by_crossing"):
            print(f"  {lat['by_crossing']} frames timed from their closing crossing's datagram;"
                  f" the same frames from their last plot's: p50 "
                  f"{1e3 * old.get('p50', math.nan):.0f} ms, p99 "
                  f"{1e3 * old.get('p99', math.nan):.0f} ms")
        print(f"  latency p50 {1e3 * lat['p50']:.0f} ms, p99 {1e3 * lat['p99']:.0f} ms "
              f"(whole run); per 10 s line p99: first {lines[0][2] if lines else 0:.0f} ms, "
              f"median {_pct([x[2] for x in lines], 50):.0f} ms, last "
              f"{lines[-1][2] if lines else 0:.0f} ms, max "
              f"{max((x[2] for x in lines), default=0):.0f} ms")
        e = r["at_end"]
        print(f"  at the replay's end (+3 s): {e['plots']} plots decoded, {e['frames']} frames "
              f"tracked; live's CPU {r['cpu_s']:.0f} s = {e['plots'] / max(r['cpu_s'], 1e-9):.0f}"
              f" plots decoded per CPU-second (the replay needs {meta['plots_per_s']:.0f}/s)")
        print(f"  RSS peak {r['rss_peak_mb']:.0f} MB, at 60 s "
              f"{next((m for t, m in r['rss'] if t >= 60), 0):.0f} MB, last "
              f"{r['rss'][-1][1] if r['rss'] else 0:.0f} MB")
        print("  p99 per status line (s, ms): " + ", ".join(
            f"{t:.0f}:{p99:.0f}" for t, _, p99 in lines))
        print(f"  $ {r['command']}")
        (d / "live_result.json").write_text(json.dumps(r, indent=1))
    if not a.skip_profile:
        from national_profile import profile

        p = profile(d, meta, a)
        how = "no profiler" if a.no_cprofile else f"cProfile, {d / 'profile.prof'}"
        print(f"\nprofile ({how}): first {a.profile_s:g} s of data, "
              f"{p['frames']} frames, {p['plots']} plots in {p['wall']:.1f} s = "
              f"{p['plots'] / p['wall']:.0f} plots/s of wall time; CPU {p['cpu']:.1f} s "
              f"= {p['plots'] / p['cpu']:.0f} plots per CPU-second")
        for label, sec in p["stages"]:
            print(f"  {label:70s} {sec:8.2f} s {100 * sec / p['cpu']:5.1f} %")  # CPU s
    s = stonesoup(d, a)
    print(f"\nslice: {a.box_km:g} km square about the centre, first {a.stonesoup_s:g} s: "
          f"{s['plots']} plots, {s['frames']} frames, {s['radars']} radars")
    print(f"  mhtrack mht-agmm: {s['mhtrack_s']:.2f} s = {s['plots'] / s['mhtrack_s']:.0f} "
          f"plots/s, {s['mhtrack_tracks']} track ids")
    if "stonesoup_s" in s:
        print(f"  Stone Soup GNN:   {s['stonesoup_s']:.2f} s = "
              f"{s['plots'] / s['stonesoup_s']:.0f} plots/s, {s['stonesoup_tracks']} track ids")


if __name__ == "__main__":
    main()
