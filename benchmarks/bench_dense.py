"""The dense scene of issue 30: 1 000 aircraft among 5 000 clutter plots per scan,
``P_D`` 0.9, 20 scans — the share of aircraft **held** over the last 10 scans and the
seconds per scan, beside a reference library measured in the same run.

Scene: ``bench_scale.py``'s ``big`` (targets on a grid in a 100 km square at 150 m/s,
uniform clutter 5·10⁻⁷ per m², one Cartesian sensor σ 100 m, ``P_D`` 0.9, scan 1 s), the
plain ``mht`` with the true κ, default settings (``default_config(scenario)``); seed 1.

**Held**: at each of the last ``--held-scans`` scans, the confirmed tracks reported at that
scan (``output="online"``: what a live tracker sends) and the aircraft are paired one to
one by a minimum-distance assignment (``scipy.optimize.linear_sum_assignment``) among the
pairs within ``--gate`` m (300 m: 3 σ); an aircraft is held when it is paired at every one
of those scans. ``held_one_id``: held, by the same track id at every one of those scans.
``held_history``: the same over the **history** view (the rows back-filled when a track is
confirmed included: ``output="history"``; the online view is its rows with ``tentative``
false, so one run gives both).

``--attributes``: the same scene and seed with secondary-radar attributes on the plots, as
``mhtrack simulate --attributes`` draws them (:func:`mhtrack.scenario.identity.
with_attributes`: per aircraft a Mode S address, a Mode 3/A code and a flight level; per
detection 5 % primary only, 10 % secondary only, 2 % garbled; clutter plots primary, no
reply); positions, times and origins unchanged.

Time: ``StepStats.seconds`` (the tracker's ``step`` alone, wall), median over all scans and
mean over the last ``--held-scans``; per stage, CPU time of the tracker's stage functions
(``bench_stages.py``'s wrappers, summed into the groups of :data:`GROUPS`).

Each library runs in its own subprocess with ``PYTHONPATH`` on its ``src``: ours (this
checkout) and the reference (``--reference``, a git revision extracted by ``git archive``;
default the main branch this work started from), in turn ``--repeat`` times; medians.

``--ours-config JSON``: ``MHTConfig`` fields changed on our side only (the reference keeps
its defaults), e.g. ``'{"startup_density": true}'`` (issue 30's start-up density); several
``--ours-config`` run as several sides of ours.

Run: ``python benchmarks/bench_dense.py [--repeat 3] [--reference REV] [--scans 20]
[--seed S] [--attributes] [--ours-config JSON ...]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

#: The main branch this work started from ("today's code path").
REFERENCE = "e1d9348"

#: Stage group → the tracker functions (``bench_stages.STAGES`` and wrapped methods) in it.
GROUPS = {
    "predict": ("predict_leaves", "MHTTracker._look", "validate_scan"),
    "gating": ("gate_looked", "plots_in_confirmed_gates"),
    "clutter": ("clutter_intensity",),
    "scoring": ("update_increment", "miss_increments"),
    "births": ("Birth.propose", "Birth.seed"),
    "children": ("propose_children",),
    "pruning": ("prune_children", "removed_after_solve", "prune_after_solve",
                "kept_after_solve", "take_kept"),
    "update (Kalman)": ("grow_children",),
    "numbering": ("number_nodes", "merge_by_tree", "number_and_merge", "number_frame"),
    "clustering": ("clustering",),
    "hypothesis (assignment)": ("best_hypothesis",),
    "attributes": ("reply_terms", "pair_increments", "MHTTracker._attributes"),
    "confirm, history, report": ("hand_over", "confirm", "newly_confirmed", "report",
                                 "confirmed_windows", "SPRT.confirms",
                                 "TentativeHistory.backfill", "TentativeHistory.record",
                                 "MHTTracker._forget", "Reported.of", "StepStats.of",
                                 "Leaves.concat"),
}


def held(tracks: object, truth: object, scans: list[int], gate: float) -> tuple[int, int]:
    """``(held, held by one id)`` of the aircraft over ``scans`` (module docstring)."""
    from scipy.optimize import linear_sum_assignment
    from scipy.spatial.distance import cdist

    ids = np.unique(truth.target_id)
    ok = np.ones(ids.size, bool)
    by = np.full((len(scans), ids.size), -1, np.int64)
    for k, s in enumerate(scans):
        tr = np.flatnonzero(tracks.scan == s)
        tt = np.flatnonzero(truth.scan == s)
        paired = np.zeros(ids.size, bool)
        if tr.size and tt.size:
            dist = cdist(tracks.positions[tr], truth.positions[tt])
            cost = np.where(dist <= gate, dist, 1e9)
            r, c = linear_sum_assignment(cost)
            keep = cost[r, c] <= gate
            col = np.searchsorted(ids, truth.target_id[tt[c[keep]]])
            paired[col] = True
            by[k, col] = tracks.track_id[tr[r[keep]]]
        ok &= paired
    one_id = ok & np.all(by == by[0], axis=0)
    return int(ok.sum()), int(one_id.sum())


def dense_scene(n_scans: int, seed: int, attributes: bool = False,
                config: dict | None = None) -> tuple[object, object, str, float]:
    """``(simulation, MHTConfig, tracker name, true κ per m²)`` of the dense scene (module
    docstring) on the library on ``sys.path``; ``config``: ``MHTConfig`` fields changed;
    ``attributes``: the plots with secondary-radar attributes. Shared by
    ``dense_bound.py`` and ``dense_held_why.py``."""
    import dataclasses
    import logging

    from bench_scale import SCENES, scene
    from mhtrack.build import default_config
    from mhtrack.scenario import simulate

    logging.getLogger("mhtrack").setLevel(logging.ERROR)
    n_targets, rate, name = SCENES["big"]
    sc = scene(n_targets, rate, n_scans)
    sim = simulate(sc, seed=seed)
    if attributes:
        from mhtrack.scenario.identity import with_attributes

        sim = with_attributes(sim)
    cfg = dataclasses.replace(default_config(sc), scale_caps=True, **(config or {}))
    return sim, cfg, name, rate / sc.region.area


def run_one(n_scans: int, seed: int, held_scans: int, gate: float,
            config: dict | None = None, attributes: bool = False) -> dict:
    """The scene on the library on ``sys.path``, in this process: the figures
    (``attributes``: the plots with secondary-radar attributes, module docstring)."""
    import bench_stages
    from mhtrack.build import make_tracker
    from mhtrack.experiments import track

    sim, cfg, name, kappa = dense_scene(n_scans, seed, attributes, config)
    trk = make_tracker(name, cfg, clutter_density=kappa)
    warm = warm_up(trk.motion)
    bench_stages.install()
    _install_clustering(bench_stages)
    _install_attributes(bench_stages)
    trk.birth.propose = bench_stages._timed("Birth.propose", trk.birth.propose)
    trk.birth.seed = bench_stages._timed("Birth.seed", trk.birth.seed)
    step, cpus = trk.step, []

    def timed_step(scan: object) -> object:
        c = time.process_time()
        try:
            return step(scan)
        finally:
            cpus.append(time.process_time() - c)

    trk.step = timed_step
    bench_stages.ACC.clear()
    c0 = time.process_time()
    run = track(trk, sim.plots, name=name, output="history")
    cpu = time.process_time() - c0
    sec = np.asarray(run.seconds_per_scan)
    last = sorted(np.unique(sim.truth.scan))[-held_scans:]
    h, h1 = held(run.tracks.online(), sim.truth, [int(s) for s in last], gate)
    hh, hh1 = held(run.tracks, sim.truth, [int(s) for s in last], gate)
    n_air = int(np.unique(sim.truth.target_id).size)
    stages = {g: sum(bench_stages.ACC.get(f, 0.0) for f in fs) / n_scans
              for g, fs in GROUPS.items()}
    stages["hypothesis (assignment)"] -= stages["clustering"]  # nested in best_hypothesis
    stages["other (step CPU − stages)"] = (
        cpu / n_scans - sum(stages.values()))  # track()'s own work is in there too
    return {"held": h / n_air, "held_one_id": h1 / n_air, "aircraft": n_air,
            "held_history": hh / n_air, "held_history_one_id": hh1 / n_air,
            "s_per_scan_median": float(np.median(sec)),
            "s_per_scan_last": float(sec[-held_scans:].mean()),
            "cpu_per_scan": cpu / n_scans,
            "cpu_step_median": float(np.median(cpus)),
            "cpu_step_last": float(np.mean(cpus[-held_scans:])), "stages": stages,
            "caps": run.caps, "plots_per_scan": len(sim.plots) / n_scans,
            "warm_up_cpu_s": warm}


def _install_clustering(bench_stages: object) -> None:
    """Time, as ``clustering``, the cluster functions the global hypothesis calls (the
    names :mod:`mhtrack.mht.hypothesis` imports from :mod:`mhtrack.mht.clustering`)."""
    import mhtrack.mht.hypothesis as H

    for name in ("tree_clusters", "dense_index", "plot_keys", "raw_plot_keys"):
        if hasattr(H, name):
            setattr(H, name, bench_stages._timed("clustering", getattr(H, name)))
    try:  # the global hypothesis called through the frame scope (not the tracker's name)
        import mhtrack.mht.frame_scope as F
    except ImportError:
        return
    if hasattr(F, "best_hypothesis"):
        F.best_hypothesis = bench_stages._timed("best_hypothesis", F.best_hypothesis)


def _install_attributes(bench_stages: object) -> None:
    """Time, as ``attributes``, the attributes' likelihood ratios and the leaves'
    vertical states, codes and addresses (the tracker's names; absent: nothing)."""
    import mhtrack.mht.tracker as T

    for name in ("reply_terms", "pair_increments"):
        if hasattr(T, name):
            setattr(T, name, bench_stages._timed(name, getattr(T, name)))
    if hasattr(T.MHTTracker, "_attributes"):
        T.MHTTracker._attributes = bench_stages._timed("MHTTracker._attributes",
                                                       T.MHTTracker._attributes)


def warm_up(motion: object) -> float:
    """CPU seconds to import and load the compiled loops (``mhtrack.models.imm_rows``,
    once per process), spent here so that the scans' times hold none of it; 0 for a
    library without them or without numba."""
    try:
        from mhtrack.models import imm_rows
    except ImportError:
        return 0.0
    from mhtrack.mht.tree import one_point_state

    c = time.process_time()
    if imm_rows.kernels(imm_rows.MIN_ROWS) is None:
        return 0.0
    n, lim = 4, imm_rows.MIN_ROWS
    imm_rows.MIN_ROWS = 1
    try:
        x, P = one_point_state(np.zeros((n, 2)), 1e4 * np.eye(2), 300.0)
        pred = motion.predict(motion.new_states(x, P), 1.0)
        motion.update(pred, np.ones((n, 2)), 1e4 * np.eye(2))
        from mhtrack.models.imm import Posterior

        idx = np.arange(n)
        motion.children_states(pred, idx, idx - 1, idx, np.ones((n, 2)), 1e4 * np.eye(2),
                               Posterior(pred.mu.copy(), np.ones(n)))
    finally:
        imm_rows.MIN_ROWS = lim
    return time.process_time() - c


def reference_src(rev: str) -> Path:
    """The library at ``rev`` (``git archive`` of ``src``) in a temporary directory."""
    d = Path(tempfile.gettempdir()) / f"mhtrack-reference-{rev}"
    if not (d / "src" / "mhtrack").is_dir():
        d.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "src"],
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(d)], input=archive, check=True)
    return d / "src"


def on_library(src: Path, a: argparse.Namespace, config: str = "{}") -> dict:
    """:func:`run_one` in a subprocess on the library in ``src`` (``config``: JSON of the
    ``MHTConfig`` fields to change)."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    cmd = [sys.executable, __file__, "--one", "--scans", str(a.scans), "--seed",
           str(a.seed), "--held-scans", str(a.held_scans), "--gate", str(a.gate),
           "--config", config] + (["--attributes"] if a.attributes else [])
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scans", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--held-scans", type=int, default=10)
    ap.add_argument("--gate", type=float, default=300.0, help="m")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each side, in turn")
    ap.add_argument("--reference", default=REFERENCE, help="git revision (or 'none')")
    ap.add_argument("--ours-config", action="append", default=None, metavar="JSON",
                    help="MHTConfig fields changed on our side (repeatable: one side each)")
    ap.add_argument("--attributes", action="store_true",
                    help="plots with secondary-radar attributes (module docstring)")
    ap.add_argument("--config", default="{}", help=argparse.SUPPRESS)  # --one's
    ap.add_argument("--one", action="store_true", help="this process, JSON out")
    a = ap.parse_args(argv)
    if a.one:
        print(json.dumps(run_one(a.scans, a.seed, a.held_scans, a.gate,
                                 json.loads(a.config), a.attributes)))
        return 0
    sides = {("ours" if c == "{}" else f"ours {c}"): (ROOT / "src", c)
             for c in (a.ours_config or ["{}"])}
    if a.reference != "none":
        sides[f"reference {a.reference}"] = (reference_src(a.reference), "{}")
    runs: dict[str, list[dict]] = {k: [] for k in sides}
    for _ in range(a.repeat):
        for k, (src, config) in sides.items():
            runs[k].append(on_library(src, a, config))
    print(f"dense scene: 1 000 aircraft x 5 000 clutter/scan, P_D 0.9, {a.scans} scans, "
          f"seed {a.seed}{', SSR attributes' if a.attributes else ''}; held over the last "
          f"{a.held_scans} scans within {a.gate:g} m; "
          f"median of {a.repeat} runs each, in turn")
    med = {}
    for k, rs in runs.items():
        med[k] = m = {key: statistics.median(r[key] for r in rs) for key in
                      ("held", "held_one_id", "held_history", "held_history_one_id",
                       "s_per_scan_median", "s_per_scan_last",
                       "cpu_per_scan", "cpu_step_median", "cpu_step_last")}
        m["stages"] = {g: statistics.median(r["stages"][g] for r in rs)
                       for g in rs[0]["stages"]}
        each = ", ".join(f"{r['s_per_scan_median']:.3f}" for r in rs)
        print(f"  {k}\n  {'':20s} held {m['held']:.3f} (one id {m['held_one_id']:.3f}; "
              f"history view {m['held_history']:.3f}, one id "
              f"{m['held_history_one_id']:.3f}), "
              f"{m['s_per_scan_median']:.3f} s/scan median (last {a.held_scans}: "
              f"{m['s_per_scan_last']:.3f}; all runs "
              f"{each}), "
              f"caps {rs[0]['caps'] or 'none'}")
        print(f"  {'':20s} CPU of the step {m['cpu_step_median']:.3f} s/scan median (last "
              f"{a.held_scans}: {m['cpu_step_last']:.3f}); whole run "
              f"{m['cpu_per_scan']:.3f} s/scan; compiled loops loaded in "
              f"{statistics.median(r['warm_up_cpu_s'] for r in rs):.2f} s CPU, once")
    keys = list(med)
    print("  CPU ms/scan by stage: " + " | ".join(keys))
    for g in med[keys[0]]["stages"]:
        print(f"    {g:28s} " + " | ".join(
            f"{1e3 * med[k]['stages'].get(g, 0.0):8.1f}" for k in keys))
    print(f"  load average {', '.join(f'{v:.1f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
