"""Every speed figure of issue 18 against its reference, measured in the same run.

    PYTHONPATH=src python benchmarks/run.py                     # all figures
    PYTHONPATH=src python benchmarks/run.py --figure crossing-agmm --figure start-help

Writes ``benchmarks/results.md`` (figure, ours, reference, ratio, target, machine). The
reference of each figure:

* Stone Soup where it applies: GNN (``GNNWith2DAssignment`` on PDA hypotheses) on the same
  ``crossing`` plots (``stonesoup_reference.py``), and on the same ``opensky-radars`` plots
  (``stonesoup_timed.py``, as ``bench_async.py``);
* otherwise the **previous release**: the library at ``--previous`` (default
  :data:`PREVIOUS`, main before issue 18's speed work), extracted with ``git archive`` to a
  temporary directory and run in a subprocess with ``PYTHONPATH`` on its ``src`` — the
  same benchmark code on the old library. Ours and the previous release run in turn,
  ``--repeat`` times each (medians), as fresh subprocesses alike.

Each pair is measured back to back in the same run, so the ratio holds while the machine is
loaded (it is shared); the absolute times are only as good as the load allows. Tracker
step times are ``StepStats.seconds`` (the tracker's ``step`` alone), medians over scans.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

#: The previous release the figures without a peer are compared with (main before the
#: speed work of issue 18).
PREVIOUS = "7f9b063"


# ------------------------------------------------------------------ ours (this process)
def crossing(tracker: str, seed: int = 1) -> dict[str, float]:
    """Median ms/scan of ``tracker`` (built as ``mhtrack run`` builds it) on ``crossing``,
    and its OSPA."""
    from mhtrack.build import default_config, make_tracker
    from mhtrack.experiments import track
    from mhtrack.metrics import evaluate
    from mhtrack.scenario import preset, simulate

    sc = preset("crossing")
    sim = simulate(sc, seed=seed)
    run = track(make_tracker(tracker, default_config(sc)), sim.plots, output="online")
    t = run.seconds_per_scan
    return {"ms_per_scan": 1e3 * float(statistics.median(t)),
            "ospa": float(evaluate(run.tracks, sim.truth, plots=sim.plots).ospa_mean)}


def stonesoup_crossing(seed: int = 1) -> dict[str, float]:
    """Stone Soup GNN on the same ``crossing`` plots (P1's parameters, true κ of the GMM
    clutter's mean rate over the region)."""
    from mhtrack.metrics import evaluate
    from mhtrack.mht import MHTConfig
    from mhtrack.scenario import preset, simulate
    from stonesoup_reference import run_stonesoup_jpda

    sc = preset("crossing")
    sim = simulate(sc, seed=seed)
    cfg = MHTConfig()
    n_clutter = int((sim.plots.origin < 0).sum()) / sim.plots.n_scans
    tracks, sec = run_stonesoup_jpda(sim.plots, sigma_w=cfg.sigma_w, sigma_v=cfg.sigma_v,
                                     p_detection=cfg.p_detection, kind="gnn",
                                     clutter_density=n_clutter / sc.region.area)
    return {"ms_per_scan": 1e3 * float(statistics.median(sec)),
            "ospa": float(evaluate(tracks, sim.truth, plots=sim.plots).ospa_mean)}


def opensky(scans: int, seed: int = 1, stonesoup: bool = False) -> dict[str, float]:
    """Wall of mhtrack (``mht-agmm`` as ``mhtrack track --sensors`` builds it) or of Stone
    Soup GNN on the first ``scans`` 10-s scans of ``opensky-radars`` (``bench_async.py``)."""
    import math

    from bench_async import score
    from mhtrack.build import default_config, make_tracker, plots_area
    from mhtrack.experiments.pipeline import track
    from mhtrack.scenario import preset, simulate

    sc = preset("opensky-radars", scans=scans or None)
    sim = simulate(sc, seed=seed)
    if stonesoup:
        from stonesoup_timed import run_stonesoup_timed

        pd = {s.id: float(p) for s, p in zip(sc.sensors, sc.pd, strict=True)}
        kappa = {s.id: (s.clutter_rate + sum(p.rate for p in s.clutter_patches))
                 / (math.pi * s.max_range**2) for s in sc.sensors}
        r = run_stonesoup_timed(sim.plots, pd=pd, clutter_density=kappa, kind="gnn")
        return {"wall_s": r.wall, "ospa": score(r.history, sim.truth)[0]}
    cfg = default_config(area=plots_area(sim.plots.x, sim.plots.y).area)
    trk = make_tracker("mht-agmm", cfg, sensors=sc.sensor_set())
    t0 = time.perf_counter()
    run = track(trk, sim.plots, name="mht-agmm", output="history")
    return {"wall_s": time.perf_counter() - t0, "ospa": score(run.tracks, sim.truth)[0]}


def hour() -> dict[str, float]:
    """An hour of three rotating radars (``bench_async.py --hour``)."""
    import contextlib
    import io

    from bench_async import throughput

    a = argparse.Namespace(seed=1, duration=3600.0, targets=20, tracker="mht-gmm")
    with contextlib.redirect_stdout(io.StringIO()):
        return throughput(a)


def scale(scene: str, scans: int) -> dict[str, float]:
    """``bench_scale.py --scene``: s/scan, coverage and peak RSS in a fresh process."""
    out = subprocess.run([sys.executable, str(HERE / "bench_scale.py"), "--scene", scene,
                          "--scans", str(scans)], capture_output=True, text=True, check=True)
    r = json.loads(out.stdout.strip().splitlines()[-1])
    return {k: r[k] for k in ("s_per_scan_median", "coverage", "peak_rss_mb")}


def start(args: list[str], runs: int = 9) -> dict[str, float]:
    """Median whole-process wall time of ``python -m``-free ``mhtrack ARGS`` (the console
    entry point called from a fresh interpreter)."""
    code = ("import sys; sys.argv = ['mhtrack'] + sys.argv[1:]; "
            "from mhtrack.cli.main import main; main()")
    walls = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code, *args], capture_output=True, check=True)
        walls.append(time.perf_counter() - t0)
    return {"wall_s": statistics.median(walls)}


def one_scan_file() -> list[str]:
    """``track`` arguments on a one-scan plots file: the first scan of ``mhtrack simulate
    crossing --seed 1``."""
    import csv

    d = Path(tempfile.mkdtemp(prefix="mhtrack-bench-"))
    start(["simulate", "crossing", "--seed", "1", "--out", str(d / "sim")], runs=1)
    with open(d / "sim" / "plots.csv", newline="") as f:
        rows = list(csv.reader(f))
    scan = rows[0].index("scan")
    with open(d / "plots.csv", "w", newline="") as f:
        csv.writer(f).writerows([rows[0]] + [r for r in rows[1:] if r[scan] == rows[1][scan]])
    return ["track", str(d / "plots.csv"), "--out", str(d / "tracks.csv")]


#: name → (what, function of the parsed arguments, key of the figure, unit, target).
FIGURES: dict[str, tuple[str, Callable[[argparse.Namespace], dict], str, str, str]] = {
    "crossing-agmm": ("crossing seed 1, MHT-AGMM, median step", lambda a:
                      crossing("mht-agmm"), "ms_per_scan", "ms/scan", "≤ 0.7 ms/scan"),
    "crossing-gmm": ("crossing seed 1, MHT-GMM, median step", lambda a:
                     crossing("mht-gmm"), "ms_per_scan", "ms/scan", "≤ 0.7 ms/scan"),
    "crossing-mht": ("crossing seed 1, plain MHT (known κ = 1e−9), median step", lambda a:
                     crossing("mht"), "ms_per_scan", "ms/scan",
                     "≤ 5 ms/scan, OSPA ≤ the reference's"),
    "opensky-radars": ("opensky-radars seed 1, first N scans, mht-agmm wall", lambda a:
                       opensky(a.opensky_scans), "wall_s", "s", "Stone Soup GNN ≥ 50×"),
    "hour": ("an hour of three radars (58 439 plots), mht-gmm wall", lambda a: hour(),
             "wall_s", "s", "≤ 15 s"),
    "scale-big": ("1 000 targets × 5 000 clutter, mht, median step", lambda a:
                  scale("big", a.scale_scans), "s_per_scan_median", "s/scan", "≤ 0.1 s/scan"),
    "scale-agmm": ("10 targets × 5 000 clutter, mht-agmm, median step", lambda a:
                   scale("agmm", a.scale_scans), "s_per_scan_median", "s/scan",
                   "≤ 0.2 s/scan"),
    "start-help": ("`mhtrack --help`, whole process, median", lambda a: start(["--help"]),
                   "wall_s", "s", "≤ 0.15 s"),
    "start-track": ("`mhtrack track` of a one-scan file, whole process, median", lambda a:
                    start(one_scan_file()), "wall_s", "s", "≤ 0.6 s"),
}

#: The Stone Soup reference of a figure (others: the previous release).
STONESOUP: dict[str, Callable[[argparse.Namespace], dict]] = {
    "crossing-agmm": lambda a: stonesoup_crossing(),
    "opensky-radars": lambda a: opensky(a.opensky_scans, stonesoup=True),
}


# ------------------------------------------------------------------ the previous release
def previous_src(rev: str) -> Path:
    """The library at ``rev`` (``git archive`` of ``src``) in a temporary directory."""
    d = Path(tempfile.gettempdir()) / f"mhtrack-previous-{rev}"
    if not (d / "src" / "mhtrack").is_dir():
        d.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "src"],
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(d)], input=archive, check=True)
    return d / "src"


def on_library(name: str, a: argparse.Namespace, src: Path) -> dict:
    """Figure ``name`` measured by this script, in a subprocess, on the library in ``src``."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    cmd = [sys.executable, __file__, "--ours-json", name,
           "--opensky-scans", str(a.opensky_scans), "--scale-scans", str(a.scale_scans)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def paired(name: str, key: str, a: argparse.Namespace) -> tuple[dict, dict]:
    """Ours and the previous release's, run in turn ``--repeat`` times (ours, previous,
    ours, …: a drift of the machine's speed hits both); each side's run with the median
    ``key``."""
    runs: dict[str, list[dict]] = {"ours": [], "previous": []}
    for _ in range(a.repeat):
        runs["ours"].append(on_library(name, a, ROOT / "src"))
        runs["previous"].append(on_library(name, a, previous_src(a.previous)))
    med = {k: sorted(v, key=lambda r: r[key])[len(v) // 2] for k, v in runs.items()}
    return med["ours"], med["previous"]


# ------------------------------------------------------------------ report
def machine() -> str:
    import numpy as np

    load = ", ".join(f"{v:.1f}" for v in os.getloadavg())
    return (f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
            f"{platform.system()} {platform.release()}, Python {platform.python_version()}, "
            f"NumPy {np.__version__}; load average at the end {load} (a shared machine: "
            f"ratios are within one run, absolute times depend on the load)")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--figure", action="append", choices=sorted(FIGURES),
                    help="run this figure only (repeatable; default all)")
    ap.add_argument("--previous", default=PREVIOUS, help="git revision of the reference")
    ap.add_argument("--opensky-scans", type=int, default=3,
                    help="opensky-radars scans of 10 s (Stone Soup takes ~10 s per scan)")
    ap.add_argument("--scale-scans", type=int, default=25)
    ap.add_argument("--repeat", type=int, default=3,
                    help="runs of each side of a figure, in turn (medians)")
    ap.add_argument("--out", type=Path, default=HERE / "results.md")
    ap.add_argument("--ours-json", metavar="FIGURE", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.ours_json:  # a subprocess of on_previous
        print(json.dumps(FIGURES[a.ours_json][1](a)))
        return 0
    rows = []
    for name in a.figure or list(FIGURES):
        what, fn, key, unit, target = FIGURES[name]
        if name in STONESOUP:  # in turn, --repeat times, medians (as paired)
            pairs = [(fn(a), STONESOUP[name](a)) for _ in range(a.repeat)]
            ours, ref = (sorted((p[i] for p in pairs), key=lambda r: r[key])[a.repeat // 2]
                         for i in (0, 1))
            ref_name = "Stone Soup GNN"
        else:
            ours, ref = paired(name, key, a)
            ref_name = f"previous release {a.previous}"
        ratio = ref[key] / ours[key]
        extra = {k: v for k, v in ours.items() if k != key}
        extra_ref = {k: v for k, v in ref.items() if k != key}
        row = (f"| {name}: {what} | {ours[key]:.4g} {unit} | {ref[key]:.4g} {unit} "
               f"({ref_name}) | {ratio:.1f}× | {target} | ours {fmt(extra)}; "
               f"reference {fmt(extra_ref)} |")
        print(row, flush=True)
        rows.append(row)
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    text = ("# Speed figures (issue 18)\n\nWritten by `python benchmarks/run.py` "
            f"({' '.join(sys.argv[1:]) or 'all figures'}), {when}.\n"
            "Ratio: reference / ours (above 1: ours is faster).\n\n"
            "| figure | ours | reference | ratio | target | other figures |\n"
            "|---|---|---|---|---|---|\n" + "\n".join(rows) + f"\n\nMachine: {machine()}.\n")
    a.out.write_text(text, encoding="utf-8")
    print(f"-> {a.out}")
    return 0


def fmt(d: dict) -> str:
    return ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                     for k, v in d.items()) or "-"


if __name__ == "__main__":
    sys.exit(main())
