"""Stage 3 of ``benchmarks/national.py``: the pipeline on the national recording's first
seconds at full speed, under ``cProfile`` (or without it, ``--no-cprofile``): plots per
wall- and CPU-second, and where the time goes, stage by stage."""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import os
import pstats
import time
from pathlib import Path


class _Enough(Exception):
    pass


def profile(d: Path, meta: dict, a: argparse.Namespace) -> dict:
    """cProfile of the pipeline on the recording's first ``--profile-s`` seconds."""
    from mhtrack.pipeline import Pipeline, TrackOptions
    from mhtrack.sinks.base import Sink

    class Stop(Sink):
        def __init__(self) -> None:
            self.t0, self.frames, self.plots = None, 0, 0

        def write(self, out) -> None:
            t = out.frame.time
            self.t0 = t if self.t0 is None else self.t0
            self.frames += 1
            self.plots += out.stats.n_plots
            if t - self.t0 > a.profile_s:
                raise _Enough

    opts = TrackOptions(new_target_density=meta["birth_density"], output="online")
    pipe = Pipeline.open(d / "radar.pcap", opts, sensors_file=str(d / "sensors.toml"),
                         reorder_window_s=a.reorder_window)
    sink = Stop()
    prof = cProfile.Profile(time.process_time)  # CPU seconds: the machine is shared
    c0, t0 = time.process_time(), time.perf_counter()
    if not a.no_cprofile:
        prof.enable()
    with contextlib.suppress(_Enough):
        pipe.run([sink])
    prof.disable()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    out = {"wall": wall, "cpu": cpu, "frames": sink.frames, "plots": sink.plots,
           "stages": []}
    if not a.no_cprofile:
        prof.dump_stats(str(d / "profile.prof"))
        out["stages"] = stages(pstats.Stats(prof))
    return out


#: Where the time goes: (label, function name, file fragment); a stage's time is the
#: cumulative time of that function in the profile.
STAGE_FUNCS = (
    ("whole run (feed)", "feed", "pipeline/run.py"),
    ("tracker step", "step", "mht/tracker.py"),
    ("  frame context, look", "_frame", "mht/tracker.py"),
    ("  look (coverage)", "_look", "mht/tracker.py"),
    ("  predict", "predict_leaves", "mht/predict.py"),
    ("  gate", "gate_looked", "mht/timed.py"),
    ("  clutter", "clutter_intensity", "mht/"),
    ("  score (update increment)", "update_increment", "mht/"),
    ("  propose children", "propose_children", "mht/extend.py"),
    ("  births: propose", "propose", "mht/births/"),
    ("  prune children", "prune_children", "mht/pruning.py"),
    ("  grow (Kalman update)", "grow_children", "mht/extend.py"),
    ("  births: seed", "seed", "mht/births/"),
    ("  number and merge", "_number", "mht/tracker.py"),
    ("  global hypothesis", "_hypothesis", "mht/tracker.py"),  # before the frame scope
    ("  global hypothesis (frame scope)", "solve", "mht/frame_scope.py"),
    ("  N-scan pruning", "prune_after_solve", "mht/pruning.py"),  # before the carried rows
    ("  N-scan pruning (rows kept)", "kept_after_solve", "mht/pruning.py"),
    ("  store after the frame (states copied)", "take_kept", "mht/pruning.py"),
    ("  confirm", "_confirm", "mht/tracker.py"),
    ("  report", "_report", "mht/tracker.py"),
    ("  statistics", "of", "mht/"),
)


def stages(stats: pstats.Stats) -> list[tuple[str, float]]:
    """Cumulative seconds of each stage of :data:`STAGE_FUNCS` found in ``stats`` (a
    function the profile does not hold is left out), the source (the run less the
    tracker's steps and the sink), and the 12 heaviest functions by own time."""
    out, cum = [], {}
    for label, fn, frag in STAGE_FUNCS:
        hits = [v[3] for (f, _, name), v in stats.stats.items()  # type: ignore[attr-defined]
                if name == fn and frag in f.replace(os.sep, "/") and "mhtrack" in f]
        if hits:
            cum[fn] = max(hits)
            out.append((label, cum[fn]))
    if "feed" in cum and "step" in cum:
        out.insert(1, ("source: read, decode, re-order, frame (run − steps)",
                       cum["feed"] - cum["step"]))
    own = sorted(stats.stats.items(), key=lambda kv: -kv[1][2])[:12]  # type: ignore[attr-defined]
    for (f, line, name), v in own:
        out.append((f"own time: {'/'.join(Path(f).parts[-2:])}:{line} {name}", v[2]))
    return out


