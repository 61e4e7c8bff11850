"""Issue 30, item 5: where ``live``'s CPU goes beyond the tracker's step, beside the
file path's, on the same recording in one run.

    python benchmarks/live_profile.py DIR [--seconds 60] [--reorder-window 0.2]
        [--no-cprofile] [--one-by-one] [--json FILE]

``DIR`` is a ``benchmarks/national.py`` scene (``radar.pcap``, ``sensors.toml``,
``meta.json``: ``national.py --out DIR --skip-live --skip-profile --skip-stonesoup``).
The recording's first ``--seconds`` of capture time are tracked twice in this process:

* **file** — ``Pipeline.open(radar_firstS.pcap)`` (what ``mhtrack track`` runs), the
  online rows into a sink that drops them;
* **live** — :class:`mhtrack.pipeline.live.Live` reading the same datagrams from a
  ``len32`` stream (a regular file as its stdin: the receiving thread reads it, one
  datagram at a time onto the queue, as it would from a socket), ``--day-from stream``,
  CAT062 out over UDP to a loopback socket nobody reads (the kernel drops them, the
  encoding and ``sendto`` are paid), the health's latency bookkeeping on; it decodes what
  has queued up as one chunk (here: the whole queue, the reader being ahead), or with
  ``--one-by-one`` each datagram alone (a feed the tracker keeps up with).

Both use the national benchmark's options (its birth density, the re-order window). CPU
is measured, not wall time (the machine is shared): the process's CPU
(``time.process_time``) per run, the main (tracking) thread's (``time.thread_time``), the
rest being the receiving thread; plots per CPU-second = plots given to the tracker over
the process's CPU. With cProfile (timer ``time.thread_time``: the main thread's CPU
only), the CPU seconds of each stage (cumulative time of the function named) and the
heaviest functions by own time; the garbage collector's CPU from ``gc.callbacks``.
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import json
import os
import pstats
import socket
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: (label, function name, file fragment): a stage's CPU is the function's cumulative
#: time in the main thread's profile (the largest entry of that name and file).
STAGES = (
    ("whole run (feed)", "feed", "pipeline/run.py"),
    ("tracker step", "step", "mht/tracker.py"),
    ("source (decode ... frames; generator resumes)", "__iter__", "sources/datagrams.py"),
    ("  queue get (main thread's side)", "__iter__", "sources/udp.py"),
    ("  receive times noted (live._arrived)", "_arrived", "pipeline/live.py"),
    ("  decode data blocks (Decoder.blocks)", "blocks", "asterix/decode.py"),
    ("    duplicate filter", "fills", "asterix/decode.py"),
    ("  time axis", "times_list", "asterix/timeaxis.py"),
    ("  columns of a chunk (_chunk)", "_chunk", "sources/datagrams.py"),
    ("    convert to the local frame (_convert)", "_convert", "sources/datagrams.py"),
    ("  re-order buffer (TimedStream.push)", "push", "sources/timed.py"),
    ("    ReorderBuffer.push", "push", "io/reorder.py"),
    ("    Framer.push", "push", "sources/framer.py"),
    ("    Scan of a frame (_scan)", "_scan", "sources/timed.py"),
    ("sinks: CAT062 over UDP", "write", "sinks/stream.py"),
    ("  cat062_blocks (encode)", "cat062_blocks", "sinks/files.py"),
    ("sinks: health (latency bookkeeping)", "write", "pipeline/health.py"),
    ("sinks: the file run's sink", "write", "live_profile.py"),
)


class _GcClock:
    """CPU seconds (this thread's) spent in the garbage collector (``gc.callbacks``)."""

    def __init__(self) -> None:
        self.total, self.n, self._t0 = 0.0, 0, 0.0

    def __call__(self, phase: str, info: dict) -> None:
        if phase == "start":
            self._t0 = time.thread_time()
        else:
            self.total += time.thread_time() - self._t0
            self.n += 1


def _len32(datagrams: list[tuple[bytes, float]], path: Path) -> Path:
    """The datagrams as a ``len32`` stream (``live --stdin len32``)."""
    with path.open("wb") as fh:
        for data, _ in datagrams:
            fh.write(len(data).to_bytes(4, "big") + data)
    return path


def _measure(run, profile: bool) -> dict:
    """CPU of ``run()`` (process, main thread, GC) and its main-thread profile."""
    gcc = _GcClock()
    gc.collect()
    gc.callbacks.append(gcc)
    prof = cProfile.Profile(time.thread_time) if profile else None
    c0, m0, w0 = time.process_time(), time.thread_time(), time.perf_counter()
    try:
        if prof is not None:
            prof.enable()
        plots = run()
    finally:
        if prof is not None:
            prof.disable()
        gc.callbacks.remove(gcc)
    cpu, main = time.process_time() - c0, time.thread_time() - m0
    out = {"plots": plots, "cpu": cpu, "main": main, "other": cpu - main,
           "wall": time.perf_counter() - w0, "gc": gcc.total, "gc_runs": gcc.n}
    if prof is not None:
        out["stages"], out["own"] = stages(pstats.Stats(prof))
    return out


def stages(st: pstats.Stats) -> tuple[list[tuple[str, float]], list[tuple[str, float]]]:
    """The cumulative CPU of each stage of :data:`STAGES` found, and the 15 heaviest
    functions by own time."""
    rows = []
    for label, fn, frag in STAGES:
        hits = [v[3] for (f, _, name), v in st.stats.items()  # type: ignore[attr-defined]
                if name == fn and frag in f.replace(os.sep, "/")]
        if hits:
            rows.append((label, max(hits)))
    own = sorted(st.stats.items(), key=lambda kv: -kv[1][2])[:15]  # type: ignore[attr-defined]
    return rows, [(f"{'/'.join(Path(f).parts[-2:])}:{line} {name}", v[2])
                  for (f, line, name), v in own]


def file_run(rec: Path, sensors: Path, opts, window: float) -> int:
    """``track``'s pipeline on the recording; plots tracked."""
    from mhtrack.pipeline import Pipeline
    from mhtrack.sinks.base import Sink

    class Drop(Sink):
        def write(self, out) -> None:
            pass

    pipe = Pipeline.open(rec, opts, sensors_file=str(sensors), reorder_window_s=window)
    pipe.run([Drop()], keep_stats=False)
    return pipe.source.stats.plots_out


def live_run(stream: Path, sensors: Path, opts, window: float, port: int,
             one_by_one: bool = False) -> dict:
    """``live`` on the ``len32`` stream, CAT062 to ``127.0.0.1:port``; its figures.
    ``one_by_one``: as if no datagram ever waited (each decoded and passed on alone: a
    feed the tracker keeps up with, datagram by datagram — the dearest case per plot)."""
    from mhtrack.io.sensors import read_sensors
    from mhtrack.pipeline.live import Live, LiveOptions

    with stream.open("rb") as fh:
        live = Live(read_sensors(sensors), opts, LiveOptions(
            stdin="len32", day_from="stream", preload=False, reorder_window_s=window,
            out_udp=(f"udp://127.0.0.1:{port}",)), stdin=fh)
        if one_by_one:
            live.reader.waiting = lambda: 0  # type: ignore[method-assign]
        res = live.run()
    return {"plots": live.source.stats.plots_out, "frames": live.source.stats.frames,
            "rows": res.sent_rows, "cat062": res.sent_datagrams}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", type=Path)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--reorder-window", type=float, default=0.2)
    ap.add_argument("--no-cprofile", action="store_true")
    ap.add_argument("--json", type=Path, default=None, help="write the figures here")
    ap.add_argument("--one-by-one", action="store_true",
                    help="live passes each datagram on alone (live_run)")
    a = ap.parse_args()
    from mhtrack.pipeline import TrackOptions
    from mhtrack.sources.replay import recording_datagrams
    from national import first_seconds

    d = a.dir
    meta = json.loads((d / "meta.json").read_text())
    rec = first_seconds(d, a.seconds)
    dgs = recording_datagrams(rec)
    stream = _len32(dgs, d / f"radar_first{a.seconds:g}s.len32")
    opts = TrackOptions(new_target_density=meta["birth_density"], output="online")
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # never read: drops
    sink.bind(("127.0.0.1", 0))
    prof = not a.no_cprofile
    print(f"{rec.name}: {len(dgs)} datagrams, the first {a.seconds:g} s; re-order window "
          f"{a.reorder_window:g} s; {'cProfile (thread CPU)' if prof else 'no profiler'}",
          flush=True)
    res = {}
    res["file"] = _measure(lambda: file_run(rec, d / "sensors.toml", opts,
                                            a.reorder_window), prof)
    got: dict = {}
    res["live"] = _measure(lambda: got.update(live_run(
        stream, d / "sensors.toml", opts, a.reorder_window, sink.getsockname()[1],
        a.one_by_one)) or got["plots"], prof)
    res["live"].update(got)
    sink.close()
    for k in ("file", "live"):
        r = res[k]
        print(f"{k:4s}: {r['plots']} plots, CPU {r['cpu']:.2f} s (main thread {r['main']:.2f}"
              f" s, other threads {r['other']:.2f} s, GC {r['gc']:.2f} s in {r['gc_runs']} "
              f"runs) = {r['plots'] / r['cpu']:.0f} plots per CPU-second "
              f"({r['plots'] / r['main']:.0f} per main-thread CPU-second); wall "
              f"{r['wall']:.1f} s")
    if prof:
        names = [lab for lab, *_ in STAGES]
        f, li = dict(res["file"]["stages"]), dict(res["live"]["stages"])
        print(f"\n{'stage (main thread CPU s)':58s} {'file':>8s} {'live':>8s}")
        for n in names:
            if n in f or n in li:
                print(f"{n:58s} {f.get(n, float('nan')):8.2f} {li.get(n, float('nan')):8.2f}")
        for k in ("file", "live"):
            print(f"\nheaviest by own time, {k}:")
            for n, s in res[k]["own"]:
                print(f"  {n:70s} {s:7.2f} s")
    if a.json is not None:
        a.json.write_text(json.dumps(res, indent=1, default=str))


if __name__ == "__main__":
    main()
