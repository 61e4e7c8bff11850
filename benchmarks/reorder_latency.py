"""Issue 30, item 3: ``live``'s latency and late drops against the re-order window.

    python benchmarks/reorder_latency.py DIR OUT [--seconds 120] [--window 0.2 0.1 0.05]
        [--release time radar] [--frames eighth sector]

``DIR`` holds a simulation and its recording (``plots.csv``, ``sensors.toml``,
``radar.pcap``: ``mhtrack simulate opensky-radars --seed 1`` then ``mhtrack export``);
for each window the recording's first ``--seconds`` are replayed at real time into
``live`` (:func:`national.live_run`: loopback only, every wait bounded) and its last
status line's figures printed: plots, frames, late drops, latency p50/p99 (a sector
frame timed from its closing crossing's datagram, the former measure from its last
plot's beside it: ``docs/live.md``), live's CPU;
for each ``--release`` and ``--frames`` of ``live`` given (``docs/live.md``, *Latency*;
``sector``: ``live --sector-frames``, frames closed at the radars' CAT034 crossings).
First, from the plots alone (no ``live``): each frame's own closing wait — from its last
plot to the first plot that closes it (its radar's next plot, or the first plot of any
radar past the frame's start plus its length: ``sources/framer.py``) — p50/p99 over the
same seconds: the part of the latency that no release order removes; then the same wait
read off the recording's framer (:func:`framer_wait`: the stream's time when the frame
leaves, window 0, by radar, less its last plot's) for each ``--frames``, and, with
``--crossings N …``, for sector frames of the plots re-exported with ``N`` CAT034
crossings per turn instead of ``mhtrack export``'s 8 (real radars send 16–32).
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--seconds", type=float, default=120.0)
    ap.add_argument("--window", type=float, nargs="+", default=[0.2, 0.1, 0.05])
    ap.add_argument("--release", nargs="+", choices=("time", "radar"), default=["time"])
    ap.add_argument("--frames", nargs="+", choices=("eighth", "sector"), default=["eighth"])
    ap.add_argument("--crossings", type=int, nargs="*", default=[])
    a = ap.parse_args()
    import national
    from mhtrack.build.radar_defaults import radar_rule
    from mhtrack.io import read_plots
    from mhtrack.io.sensors import read_sensors
    from mhtrack.mht import MHTConfig

    a.out.mkdir(parents=True, exist_ok=True)
    for f in ("radar.pcap", "sensors.toml"):
        if not (a.out / f).exists():
            shutil.copy(a.dir / f, a.out / f)
    sensors = read_sensors(a.dir / "sensors.toml")
    p = read_plots(a.dir / "plots.csv", sensors)
    rule = radar_rule(sensors, p.sensor, p.time, p.x, p.y, v_max=MHTConfig().v_max)
    meta = {"birth_density": rule.new_target_density}  # track's radar rule
    wait = own_close_wait(p.time, p.sensor, sensors, a.seconds)
    print(f"own closing wait after a frame's last plot (first {a.seconds:g} s, "
          f"{wait.size} frames): p50 {1e3 * np.percentile(wait, 50):.0f} ms, p99 "
          f"{1e3 * np.percentile(wait, 99):.0f} ms", flush=True)
    for frames in a.frames:
        wait = framer_wait(a.dir / "radar.pcap", sensors, a.seconds, frames == "sector")
        print(f"{frames} frames, closing wait read off the framer ({wait.size} frames): "
              f"p50 {1e3 * np.percentile(wait, 50):.0f} ms, p99 "
              f"{1e3 * np.percentile(wait, 99):.0f} ms", flush=True)
    for n in a.crossings:
        pcap = reexport(a.dir, a.out, n)
        wait = framer_wait(pcap, sensors, a.seconds, True)
        print(f"sector frames, {n} crossings a turn, closing wait read off the framer "
              f"({wait.size} frames): p50 {1e3 * np.percentile(wait, 50):.0f} ms, p99 "
              f"{1e3 * np.percentile(wait, 99):.0f} ms", flush=True)
    for frames, release, w in ((f, r, w) for f in a.frames for r in a.release
                               for w in a.window):
        run = national.live_run(a.out, meta, argparse.Namespace(
            reorder_window=w, stop_timeout=60.0, live_s=a.seconds, release=release,
            frames=frames))
        st = run["status"]
        lat = st["latency_s"]
        print(f"{frames} frames, release {release}, window {w:g} s: {st['plots']} plots, "
              f"{st['frames']} "
              f"frames, late drops "
              f"{st['late_drops']} (crossings {st.get('late_crossings', 0)}), "
              f"latency p50 {1e3 * lat['p50']:.0f} ms p99 "
              f"{1e3 * lat['p99']:.0f} ms ({lat['count']} timed, "
              f"{lat.get('by_crossing', 0)} from the closing crossing; from the last "
              f"plot: p50 {1e3 * lat['last_plot']['p50']:.0f} ms p99 "
              f"{1e3 * lat['last_plot']['p99']:.0f} ms); live's CPU "
              f"{run['cpu_s']:.1f} s; p99 per 10 s line (ms) "
              f"{[round(x[2]) for x in run['lines']]}", flush=True)


def own_close_wait(time, sensor, sensors, seconds: float) -> np.ndarray:
    """Each frame's wait from its last plot to the plot that closes it (module
    docstring), frames of the first ``seconds`` (s; frames the data never closes left
    out)."""
    from mhtrack.frames import frame_lengths, make_frames

    order = np.argsort(np.asarray(time, float), kind="stable")
    t, s = np.asarray(time, float)[order], np.asarray(sensor, np.int64)[order]
    keep = t < t[0] + seconds
    t, s = t[keep], s[keep]
    lengths = frame_lengths({x.id: x.period for x in sensors.sensors})
    frame, _ = make_frames(t, s, lengths)
    out = []
    for k in range(int(frame.max()) + 1):
        idx = np.flatnonzero(frame == k)
        sid, start, end = int(s[idx[0]]), t[idx].min(), t[idx].max()
        mine = np.flatnonzero((s == sid) & (t > end))
        past = np.flatnonzero(t > start + lengths.get(sid, np.inf))
        close = min(t[mine[0]] if mine.size else np.inf, t[past[0]] if past.size else np.inf)
        if np.isfinite(close):
            out.append(close - end)
    return np.asarray(out)


def framer_wait(pcap: Path, sensors, seconds: float, sectors: bool) -> np.ndarray:
    """Each frame's wait from its last plot to the time the stream had reached when the
    recording's framer gave it out — one datagram at a time, re-order window 0, release
    by radar, so the wait is the frame's own closing (the next plot, the eighth, or with
    ``sectors`` its radar's next CAT034 crossing) — for frames whose last plot is within
    the first ``seconds``."""
    from mhtrack.sources.datagrams import DatagramSource
    from mhtrack.sources.replay import recording_datagrams

    grams = [d for d, _ in recording_datagrams(pcap)]
    src = DatagramSource(grams, sensors=sensors, sectors=sectors, chunk=1,
                         reorder_window_s=0.0, release="radar")
    out, t0 = [], None
    for f in src:
        t0 = float(f.t.min()) if t0 is None else t0
        if f.t.max() > t0 + seconds:
            break
        out.append(src._stream.framer.now - float(f.t.max()))
    return np.asarray(out)


def reexport(d: Path, out: Path, crossings: int) -> Path:
    """``d/plots.csv`` exported as a pcap with ``crossings`` CAT034 sector crossings per
    turn (``encode.SECTORS`` set for the call)."""
    from mhtrack.io.asterix import api, encode
    from mhtrack.io.sensors import read_sensors

    path = out / f"radar_{crossings}.pcap"
    old = encode.SECTORS
    encode.SECTORS = crossings
    try:
        api.export(d / "plots.csv", read_sensors(d / "sensors.toml"), path)
    finally:
        encode.SECTORS = old
    return path


if __name__ == "__main__":
    main()
