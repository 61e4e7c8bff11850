"""Reproduce P2 (Gong, Dai & Ma 2013): the θ sweeps of Figs. 3–4, Figs. 2 and 12–15,
Tables 1–2, on the ``multiradar`` preset (``docs/initiation.md``).

:func:`reproduce_p2` runs (or resumes) three kinds of jobs, each a chunk of runs, through a
local process pool or a Dask scheduler, saving each job's counts to
``DIR/jobs/<name>.json`` (atomically) as it finishes; a rerun skips finished jobs whose
stored parameters match:

* ``grid`` — one grid point ``(σr, λ)`` of P2 Fig. 3 (``σr ∈ {20 … 60}`` m at
  ``λ = 50``) or Fig. 4 (``λ ∈ {50 … 250}`` at ``σr = 20`` m; the shared point is run
  once). Each run is simulated and fused (adaptive K-means) **once**, and the modified
  3/4 logic is evaluated for every angle limit ``θ`` on the same fused windows by
  :func:`sweep_modified_logic`, which gives exactly the tracks of
  ``make_initiator("modified-logic", theta_deg=θ)`` for all ``θ`` in one pass;
* ``clustering`` — P2 Fig. 2 / Table 1: adaptive vs random-start K-means (oracle ``k``)
  on every scan without clutter (P2's clustering figures and its ``O(nkt) ≈ 890`` imply
  ≈ 30 plots, i.e. no clutter): ``k_correct_rate`` and time per scan;
* ``methods`` — P2 Figs. 12–15 / Table 2: the four initiators at ``σr = 20`` m,
  ``λ = 50``, ``θ = 20°`` (CLI settings): ``p_true``, ``p_false`` and time per window.

Run ``r`` simulates with ``run_seeds(seed, r + 1)[r]`` (the seed ``mhtrack initiate
--seed S`` uses for its run ``r``): it depends on ``seed`` and ``r`` only, so every θ and
every method sees the same plots. ``λ`` is the clutter rate per radar per scan (3 radars).

Outputs in ``DIR``: ``fig2_clustering.png``, ``fig3_ptrue_theta.png``,
``fig4_pfalse_theta.png``, ``fig12_15_initiated.png``, ``tables.md``, ``report.md``,
``results.json``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.experiments.montecarlo import atomic_write, execute
from mhtrack.initiation import INITIATORS, Window, make_initiator
from mhtrack.initiation.logic import sweep_modified_logic
from mhtrack.initiation.runs import fuse, fused_scans, n_targets_seen, run_seeds
from mhtrack.initiation.window import sliding_windows
from mhtrack.metrics.initiation import initiable_targets, track_targets
from mhtrack.scenario import Scenario, preset, simulate

#: P2 §2.2: θ ∈ {0, π/18, …, π} (degrees).
THETAS_DEG: tuple[float, ...] = tuple(float(10 * i) for i in range(19))
#: P2 Fig. 3: range errors (m) at λ = 50.
SIGMAS: tuple[float, ...] = (20.0, 30.0, 40.0, 50.0, 60.0)
#: P2 Fig. 4: clutter rates per scan at σr = 20 m.
RATES: tuple[float, ...] = (50.0, 100.0, 150.0, 200.0, 250.0)
#: P2's nominal setting (§2.2, §3).
SIGMA0, RATE0, THETA0 = 20.0, 50.0, 20.0
#: Runs per job (a job is one grid point × a chunk of runs).
CHUNK = 50
#: Initiator settings (those of ``mhtrack initiate``; P2's r = 300 m, Nθ = Nρ = 90, 4 votes).
LOGIC_PARAMS: dict[str, float] = {"gate_radius": 300.0, "v_min": 50.0, "v_max": 400.0}

#: P2's printed numbers (SPEC §7; P2 Tables 1–2), their machine, their code.
PAPER_T_CLUSTER = {"random": 0.045, "adaptive": 0.034}
PAPER_T_INIT = {"logic": 0.17, "modified-logic": 0.18, "hough": 114.5,
                "modified-hough": 7.29}
PAPER_COMPLEXITY = {"random": 890, "adaptive": 585}
METHOD_LABELS = {"logic": "3/4 logic", "modified-logic": "modified 3/4 logic",
                 "hough": "Hough", "modified-hough": "modified Hough"}
CLUSTER_LABELS = {"random": "K-means, random start (oracle k)",
                  "adaptive": "adaptive K-means (P2 §1.2)"}

FIGURES = {"fig2": "fig2_clustering.png", "fig3": "fig3_ptrue_theta.png",
           "fig4": "fig4_pfalse_theta.png", "fig12_15": "fig12_15_initiated.png"}
TABLES_FILE, REPORT_FILE, RESULTS_FILE, JOBS_DIR = ("tables.md", "report.md",
                                                    "results.json", "jobs")




# ---------------------------------------------------------------------- jobs
def p2_scenario(sigma_range: float = SIGMA0, clutter_rate: float = RATE0) -> Scenario:
    """``multiradar`` with every radar's range σ set to ``sigma_range`` (m) and
    ``clutter_rate`` clutter plots per radar per scan."""
    return preset("multiradar", clutter_rate=clutter_rate, sigma_range=sigma_range)


def _seed_of(seed: int, run: int) -> int:
    return run_seeds(seed, run + 1)[run]


def _initiable(raw_win: Sequence[Any]) -> np.ndarray:
    seen = np.concatenate([np.unique(s.origin[s.origin >= 0]) for s in raw_win])
    ids, n_seen = np.unique(seen, return_counts=True)
    return initiable_targets(ids, n_seen)


def _score(window: Window, flat: np.ndarray, targets: np.ndarray) -> tuple[int, int, int]:
    """(targets found, false tracks, tracks) of ``flat`` tracks in ``window``."""
    if len(flat) == 0:
        return 0, 0, 0
    o = np.where(flat >= 0, window.origin[np.maximum(flat, 0)], -2)  # type: ignore[index]
    tt = track_targets(o)
    return int(np.isin(targets, tt[tt >= 0]).sum()), int((tt < 0).sum()), len(tt)


def grid_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """One ``grid`` job: runs ``start … stop − 1`` at ``(sigma, rate)``, every θ.
    Returns plain per-θ counts summed over the runs' windows."""
    sc = p2_scenario(job["sigma"], job["rate"])
    thetas = job["thetas"]
    n = len(thetas)
    found, false, tracks = np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, np.int64)
    n_targets = n_windows = non_monotone = 0
    t0 = time.perf_counter()
    for r in range(job["start"], job["stop"]):
        rs = _seed_of(job["seed"], r)
        raw = list(simulate(sc, rs).plots.scans())
        fused, _ = fused_scans(raw, "adaptive-kmeans", run_seed=rs)
        for raw_win, win in zip(sliding_windows(raw, 4), sliding_windows(fused, 4),
                                strict=True):
            w = Window.from_scans(win)
            targets = _initiable(raw_win)
            n_targets += len(targets)
            n_windows += 1
            per = [_score(w, f, targets) for f in sweep_modified_logic(w, thetas,
                                                                        **LOGIC_PARAMS)]
            a = np.array(per, np.int64).reshape(n, 3)
            found += a[:, 0]
            false += a[:, 1]
            tracks += a[:, 2]
            non_monotone += int((np.diff(a[np.argsort(thetas), 2]) < 0).any())
    return {"found": found.tolist(), "false": false.tolist(), "tracks": tracks.tolist(),
            "n_targets": n_targets, "n_windows": n_windows,
            "non_monotone_windows": non_monotone, "seconds": time.perf_counter() - t0}


def clustering_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """One ``clustering`` job: adaptive vs random-start K-means on every scan (no clutter)."""
    sc = p2_scenario(job["sigma"], job["rate"])
    out: dict[str, Any] = {m: {"k_correct": 0, "seconds": 0.0, "clusters": 0}
                           for m in ("adaptive", "random")}
    n_scans = 0
    for r in range(job["start"], job["stop"]):
        rs = _seed_of(job["seed"], r)
        for scan in simulate(sc, rs).plots.scans():
            n_scans += 1
            k_true = n_targets_seen(scan)
            for m in ("adaptive", "random"):
                t0 = time.perf_counter()
                f = fuse(scan, m, run_seed=rs)
                out[m]["seconds"] += time.perf_counter() - t0
                out[m]["k_correct"] += int(f.n_clusters == k_true)
                out[m]["clusters"] += int(f.n_clusters)
    out["n_scans"] = n_scans
    return out


def _initiators(region: tuple[float, ...]) -> dict[str, Any]:
    out = {}
    for m in INITIATORS:
        p: dict[str, Any] = {"v_min": LOGIC_PARAMS["v_min"], "v_max": LOGIC_PARAMS["v_max"]}
        if m.endswith("logic"):
            p["gate_radius"] = LOGIC_PARAMS["gate_radius"]
        else:
            p["region"] = region
        out[m] = make_initiator(m, theta_deg=THETA0, **p)
    return out


def methods_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """One ``methods`` job: the four initiators at θ = 20° (time per window: stacking
    the fused window + initiating, as ``mhtrack initiate``)."""
    sc = p2_scenario(job["sigma"], job["rate"])
    inits = _initiators(sc.region.as_tuple())
    out: dict[str, Any] = {m: {"found": 0, "false": 0, "tracks": 0, "seconds": 0.0}
                           for m in INITIATORS}
    n_targets = n_windows = n_scans = 0
    fusion_seconds = 0.0
    for r in range(job["start"], job["stop"]):
        rs = _seed_of(job["seed"], r)
        raw = list(simulate(sc, rs).plots.scans())
        fused, secs = fused_scans(raw, "adaptive-kmeans", run_seed=rs)
        fusion_seconds += sum(secs)
        n_scans += len(secs)
        for raw_win, win in zip(sliding_windows(raw, 4), sliding_windows(fused, 4),
                                strict=True):
            targets = _initiable(raw_win)
            n_targets += len(targets)
            n_windows += 1
            for m, ini in inits.items():
                t0 = time.perf_counter()
                w = Window.from_scans(win)
                tr = ini.initiate(w)
                out[m]["seconds"] += time.perf_counter() - t0
                f, fa, n = _score(w, tr.flat, targets)
                out[m]["found"] += f
                out[m]["false"] += fa
                out[m]["tracks"] += n
    out.update(n_targets=n_targets, n_windows=n_windows, n_scans=n_scans,
               fusion_seconds=fusion_seconds)
    return out


JOB_FUNCTIONS: dict[str, Callable[[Mapping[str, Any]], dict[str, Any]]] = {
    "grid": grid_job, "clustering": clustering_job, "methods": methods_job}


def run_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """Run one job (top level, picklable: what the pool / Dask workers call)."""
    return JOB_FUNCTIONS[job["kind"]](job)


def _hash(d: Mapping[str, Any]) -> str:
    return hashlib.sha256(json.dumps(d, sort_keys=True).encode()).hexdigest()


def make_jobs(runs: int, seed: int, thetas: Sequence[float], sigmas: Sequence[float],
              rates: Sequence[float], chunk: int = CHUNK) -> list[dict[str, Any]]:
    """All jobs of a study (module docstring); each a plain dict with a unique ``name``."""
    points = [(float(s), RATE0) for s in sigmas] + [(SIGMA0, float(r)) for r in rates]
    points = list(dict.fromkeys(points))
    chunks = [(a, min(a + chunk, runs)) for a in range(0, runs, chunk)]
    jobs = []

    def add(kind: str, name: str, sigma: float, rate: float, a: int, b: int,
            **extra: Any) -> None:
        j: dict[str, Any] = {"kind": kind, "name": f"{name}-r{a}-{b}", "sigma": sigma,
                             "rate": rate, "start": a, "stop": b, "seed": int(seed), **extra}
        j["job_hash"] = _hash(j)
        j["tracker"], j["run"] = kind, a  # keys the Dask runner names its tasks with
        jobs.append(j)

    for a, b in chunks:
        for s, r in points:
            add("grid", f"grid-s{s:g}-l{r:g}", s, r, a, b, thetas=[float(x) for x in thetas])
        add("clustering", "clustering-s20-l0", SIGMA0, 0.0, a, b)
        add("methods", f"methods-s{SIGMA0:g}-l{RATE0:g}", SIGMA0, RATE0, a, b)
    return jobs


def _done(path: Path, job: Mapping[str, Any]) -> dict[str, Any] | None:
    """The stored result of ``job`` if ``path`` holds it (same parameters)."""
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return d["result"] if d.get("job", {}).get("job_hash") == job["job_hash"] else None


def run_jobs(jobs: Sequence[Mapping[str, Any]], jobs_dir: Path, *, executor: str = "local",
             workers: int | None = None, scheduler: Any = None, progress: bool = False,
             ) -> tuple[dict[str, dict[str, Any]], dict[str, str], int]:
    """Run the jobs not finished in ``jobs_dir``; returns (results by name, errors by
    name, number computed)."""
    from tqdm.auto import tqdm


    results: dict[str, dict[str, Any]] = {}
    errors: dict[str, str] = {}
    pending = []
    for j in jobs:
        r = _done(jobs_dir / f"{j['name']}.json", j)
        if r is None:
            pending.append(j)
        else:
            results[j["name"]] = r
    bar = tqdm(total=len(pending), desc="reproduce p2", unit="job", disable=not progress)

    def finish(job: Mapping[str, Any], record: Mapping[str, Any] | None,
               error: str | None) -> None:
        bar.update(1)
        if error is not None:
            errors[job["name"]] = error
            atomic_write(jobs_dir / f"{job['name']}.error.txt", error)
            return
        results[job["name"]] = dict(record)  # type: ignore[arg-type]
        atomic_write(jobs_dir / f"{job['name']}.json",
                      json.dumps({"job": dict(job), "result": record}) + "\n")
        (jobs_dir / f"{job['name']}.error.txt").unlink(missing_ok=True)

    jobs_dir.mkdir(parents=True, exist_ok=True)
    try:
        execute(pending, run_job, finish, executor=executor, workers=workers,
                scheduler=scheduler)
    finally:
        bar.close()
    return results, errors, len(pending)


# ---------------------------------------------------------------------- aggregation
def _ratio(a: float, b: float) -> float | None:
    return a / b if b else None


def aggregate(jobs: Sequence[Mapping[str, Any]], results: Mapping[str, Mapping[str, Any]],
              thetas: Sequence[float]) -> dict[str, Any]:
    """Sum the jobs' counts into curves and tables (plain JSON-able dict)."""
    n = len(thetas)
    grid: dict[tuple[float, float], dict[str, Any]] = {}
    clus: dict[str, Any] = {m: {"k_correct": 0, "seconds": 0.0, "clusters": 0}
                            for m in ("adaptive", "random")}
    clus["n_scans"] = 0
    meth: dict[str, Any] = {m: {"found": 0, "false": 0, "tracks": 0, "seconds": 0.0}
                            for m in INITIATORS}
    meth.update(n_targets=0, n_windows=0, n_scans=0, fusion_seconds=0.0)
    runs_done: dict[str, int] = {}
    for j in jobs:
        r = results.get(j["name"])
        if r is None:
            continue
        if j["kind"] == "grid":
            key = (j["sigma"], j["rate"])
            g = grid.setdefault(key, {"found": np.zeros(n, np.int64),
                                      "false": np.zeros(n, np.int64),
                                      "tracks": np.zeros(n, np.int64), "n_targets": 0,
                                      "n_windows": 0, "non_monotone_windows": 0, "runs": 0})
            for k in ("found", "false", "tracks"):
                g[k] += np.asarray(r[k], np.int64)
            for k in ("n_targets", "n_windows", "non_monotone_windows"):
                g[k] += r[k]
            g["runs"] += j["stop"] - j["start"]
        elif j["kind"] == "clustering":
            for m in ("adaptive", "random"):
                for k in ("k_correct", "seconds", "clusters"):
                    clus[m][k] += r[m][k]
            clus["n_scans"] += r["n_scans"]
            runs_done["clustering"] = runs_done.get("clustering", 0) + j["stop"] - j["start"]
        else:
            for m in INITIATORS:
                for k in ("found", "false", "tracks", "seconds"):
                    meth[m][k] += r[m][k]
            for k in ("n_targets", "n_windows", "n_scans", "fusion_seconds"):
                meth[k] += r[k]
            runs_done["methods"] = runs_done.get("methods", 0) + j["stop"] - j["start"]

    def curve(g: Mapping[str, Any]) -> dict[str, Any]:
        return {"p_true": [_ratio(int(f), g["n_targets"]) for f in g["found"]],
                "p_false": [_ratio(int(f), int(t)) for f, t in zip(g["false"], g["tracks"],
                                                                  strict=True)],
                "tracks_per_window": [_ratio(int(t), g["n_windows"]) for t in g["tracks"]],
                "found": g["found"].tolist(), "false": g["false"].tolist(),
                "tracks": g["tracks"].tolist(), "n_targets": g["n_targets"],
                "n_windows": g["n_windows"], "runs": g["runs"],
                "non_monotone_windows": g["non_monotone_windows"]}

    curves = [{"sigma_range": s, "clutter_rate": r, **curve(g)}
              for (s, r), g in sorted(grid.items())]
    ns = clus["n_scans"]
    clustering = {m: {"k_correct_rate": _ratio(clus[m]["k_correct"], ns),
                      "mean_clusters": _ratio(clus[m]["clusters"], ns),
                      "t_scan": _ratio(clus[m]["seconds"], ns),
                      "paper_t_scan": PAPER_T_CLUSTER[m]} for m in ("adaptive", "random")}
    clustering.update(n_scans=ns, runs=runs_done.get("clustering", 0),  # type: ignore[arg-type]
                      clutter_rate=0.0, sigma_range=SIGMA0)
    nw = meth["n_windows"]
    methods = {m: {"p_true": _ratio(meth[m]["found"], meth["n_targets"]),
                   "p_false": _ratio(meth[m]["false"], meth[m]["tracks"]),
                   "tracks_per_window": _ratio(meth[m]["tracks"], nw),
                   "false_per_window": _ratio(meth[m]["false"], nw),
                   "t_window": _ratio(meth[m]["seconds"], nw),
                   "paper_t_window": PAPER_T_INIT[m]} for m in INITIATORS}
    methods.update(n_windows=nw, runs=runs_done.get("methods", 0),  # type: ignore[arg-type]
                   t_fusion_scan=_ratio(meth["fusion_seconds"], meth["n_scans"]),
                   sigma_range=SIGMA0, clutter_rate=RATE0, theta_deg=THETA0)
    return {"thetas_deg": [float(x) for x in thetas], "curves": curves,
            "clustering": clustering, "methods": methods}


def curve_for(res: Mapping[str, Any], sigma: float, rate: float) -> dict[str, Any] | None:
    for c in res["curves"]:
        if c["sigma_range"] == sigma and c["clutter_rate"] == rate:
            return c
    return None


# ---------------------------------------------------------------------- figures
def _nan(v: Sequence[float | None]) -> np.ndarray:
    return np.array([np.nan if x is None else x for x in v], float)


def _curve_figure(res: Mapping[str, Any], key: str, points: Sequence[tuple[float, float]],
                  label: Callable[[float, float], str], title: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    th = np.asarray(res["thetas_deg"])
    o = np.argsort(th)
    fig, ax = plt.subplots(figsize=(7, 4.6))
    for s, r in points:
        c = curve_for(res, s, r)
        if c is not None:
            ax.plot(th[o], _nan(c[key])[o], "o-", ms=3.5, label=label(s, r))
    ax.axvline(THETA0, color="0.6", ls=":", lw=1, label="θ = 20° (P2's choice)")
    ax.set_xlabel("angle limit θ (deg)")
    ax.set_ylabel(key)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xticks(np.arange(0, 181, 20))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _tracks_figure(seed: int, path: Path) -> None:
    import matplotlib.pyplot as plt

    from mhtrack.plotting.initiation import _finish, _zoom, draw_tracks, draw_window

    sc = p2_scenario(SIGMA0, RATE0)
    rs = _seed_of(seed, 0)
    sim = simulate(sc, rs)
    raw = list(sim.plots.scans())
    fused, _ = fused_scans(raw, "adaptive-kmeans", run_seed=rs)
    win = Window.from_scans(next(iter(sliding_windows(fused, 4))))
    truth = sim.truth.positions[np.isin(sim.truth.scan, win.scans)]
    fig, axes = plt.subplots(2, 2, figsize=(11, 10))
    figno = {"modified-logic": 12, "logic": 13, "hough": 14, "modified-hough": 15}
    for ax, m in zip(axes.ravel(), ("modified-logic", "logic", "hough", "modified-hough"),
                     strict=True):
        tr = _initiators(sc.region.as_tuple())[m].initiate(win)
        draw_window(ax, win)
        draw_tracks(ax, win, tr)
        _zoom(ax, truth)
        _finish(ax, f"P2 Fig. {figno[m]}: {METHOD_LABELS[m]}")
        h, lab = ax.get_legend_handles_labels()
        keep = [i for i, s in enumerate(lab) if "tracks" in s]
        ax.legend([h[i] for i in keep], [lab[i] for i in keep], fontsize=8, loc="upper right")
    fig.suptitle(f"multiradar, run 0, scans {win.scans[0]}–{win.scans[-1]}, σr = 20 m, "
                 f"λ = 50, θ = 20°, adaptive K-means fusion")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _clustering_figure(seed: int, path: Path) -> None:
    import matplotlib.pyplot as plt

    from mhtrack.plotting.initiation import clustering_figure_for

    # the first scan of run 0 where random-start K-means gets k wrong (P2 Fig. 2(a)
    # shows such a failure); scan 0 if there is none
    sc = p2_scenario(SIGMA0, 0.0)
    rs = _seed_of(seed, 0)
    number = 0
    for i, scan in enumerate(simulate(sc, rs).plots.scans()):
        if fuse(scan, "random", run_seed=rs).n_clusters != n_targets_seen(scan):
            number = i
            break
    fig = clustering_figure_for(sc, seed, scan_number=number)
    fig.savefig(path, dpi=100)
    plt.close(fig)


# ---------------------------------------------------------------------- text
def _f(v: float | None, d: int = 3) -> str:
    return "–" if v is None or not math.isfinite(v) else f"{v:.{d}f}"


def _ms(v: float | None) -> str:
    return "–" if v is None else f"{1e3 * v:.2f} ms"


def tables_markdown(res: Mapping[str, Any]) -> str:
    cl, me = res["clustering"], res["methods"]
    lines = [
        "# P2 Tables 1–2: ours beside the paper's",
        "",
        f"## Table 1 — clustering, time per scan (`multiradar`, no clutter, σr = 20 m; "
        f"{cl['runs']} runs, {cl['n_scans']} scans)",
        "",
        "| algorithm | P2 O(nkt) | P2 time/s | ours time/scan | ours k_correct_rate | "
        "ours mean k |",
        "|---|---|---|---|---|---|",
    ]
    for m in ("random", "adaptive"):
        c = cl[m]
        lines.append(f"| {CLUSTER_LABELS[m]} | {PAPER_COMPLEXITY[m]} | {PAPER_T_CLUSTER[m]} | "
                     f"{_ms(c['t_scan'])} | {_f(c['k_correct_rate'])} | "
                     f"{_f(c['mean_clusters'], 2)} |")
    lines += [
        "",
        f"## Table 2 — initiation, time per 4-scan window (σr = 20 m, λ = 50 per radar, "
        f"θ = 20°; {me['runs']} runs, {me['n_windows']} windows; fusion excluded: "
        f"{_ms(me['t_fusion_scan'])} per scan)",
        "",
        "| method | P2 time/s | ours time/window | ours p_true | ours p_false | "
        "ours false/window |",
        "|---|---|---|---|---|---|",
    ]
    for m in INITIATORS:
        c = me[m]
        lines.append(f"| {METHOD_LABELS[m]} | {PAPER_T_INIT[m]} | {_ms(c['t_window'])} | "
                     f"{_f(c['p_true'])} | {_f(c['p_false'])} | "
                     f"{_f(c['false_per_window'], 2)} |")
    lines += ["", "P2's times are from its machine and code (neither described in the "
              "paper); ours from this machine, measured while the other jobs ran in "
              "parallel.", ""]
    return "\n".join(lines)


def _speed_ratio(d: Mapping[str, Any], a: str, b: str, key: str) -> float | None:
    x, y = d[a][key], d[b][key]
    return x / y if x and y else None


def comparison_text(res: Mapping[str, Any]) -> list[str]:
    """Bullet points comparing our measured numbers with P2's claims."""
    th = np.asarray(res["thetas_deg"])
    o = np.argsort(th)
    th = th[o]
    out = []
    c0 = curve_for(res, SIGMA0, RATE0)
    if c0 is not None:
        p = _nan(c0["p_true"])[o]
        if np.isfinite(p).any():
            best = float(np.nanmax(p))
            first = th[np.flatnonzero(p >= best - 0.005)[0]]
            at20 = p[th == THETA0][0] if (th == THETA0).any() else np.nan
            falls = bool(p[-1] < best - 0.02)
            if abs(first - THETA0) <= 5 and falls:
                verdict = "Ours peaks at 20° as P2's does."
            elif not falls:
                verdict = (f"Ours has no peak: p_true rises until θ ≈ {first:g}° and then "
                           f"stays at its maximum up to {th[-1]:g}°. With fused-plot noise "
                           f"the leg angle of true tracks often exceeds 20° "
                           f"(docs/initiation.md §4), and a larger θ only admits more legs.")
            else:
                verdict = (f"Ours reaches its maximum at θ ≈ {first:g}°, not at 20°, "
                           f"and falls to {p[-1]:.3f} at {th[-1]:g}°.")
            out.append(
                f"**Peak of p_true (σr = 20 m, λ = 50).** P2: maximum at θ = 20°. Ours: "
                f"maximum {best:.3f}, first reached (within 0.005) at θ = {first:g}°; "
                f"p_true(20°) = {_f(at20)}. " + verdict)
            mirror = [(a, b) for a, b in zip(th, th[::-1], strict=True) if a < b]
            diffs = [abs(p[th == a][0] - p[th == b][0]) for a, b in mirror]
            if diffs and np.isfinite(diffs).all():
                out.append(
                    f"**Symmetry about π/2.** P2 says the p_true curve is symmetric about "
                    f"θ = 90° (rise, plateau, fall). Ours: max |p(θ) − p(180° − θ)| = "
                    f"{max(diffs):.3f} (e.g. p(0°) = {_f(p[0])}, p(180°) = {_f(p[-1])}). "
                    + ("Ours is not symmetric: a larger θ only admits more legs, so "
                       "p_true cannot fall back to 0 at θ = 180° (where the modified logic "
                       "is the plain 3/4 logic). The only way p_true drops with θ is a miss "
                       "branch disappearing when a clutter plot enters the gate, which is "
                       "rare. P2's symmetric curve does not follow from the angle test "
                       "as P2 states it."
                       if max(diffs) > 0.05 else "Ours is close to symmetric."))
            drop = float(max(0.0, -np.nanmin(np.diff(p)))) if len(p) > 1 else 0.0
            out.append(f"Largest drop of p_true between consecutive θ at σr = 20 m: "
                       f"{drop:.4f}.")
    sig = sorted({c["sigma_range"] for c in res["curves"] if c["clutter_rate"] == RATE0})
    if len(sig) > 1 and (th == THETA0).any():
        at = [_nan(curve_for(res, s, RATE0)["p_true"])[o][th == THETA0][0]  # type: ignore[index]
              for s in sig]
        out.append("**p_true against σr at θ = 20°:** "
                   + ", ".join(f"σr = {s:g} m: {_f(v)}" for s, v in zip(sig, at, strict=True))
                   + ". P2 says the best θ depends on σr; larger range errors bend the "
                   "legs more, so a fixed θ = 20° loses more true tracks as σr grows.")
    rates = sorted({c["clutter_rate"] for c in res["curves"] if c["sigma_range"] == SIGMA0})
    if rates:
        pf = {r: _nan(curve_for(res, SIGMA0, r)["p_false"])[o] for r in rates}  # type: ignore[index]
        steps = [np.diff(v[np.isfinite(v)]) for v in pf.values()]
        n_up = sum(int((s >= 0).sum()) for s in steps)
        n_all = sum(len(s) for s in steps)
        txt = (f"**p_false against θ.** P2: grows with θ (Fig. 4). Ours: "
               f"{n_up} of {n_all} steps between consecutive θ are non-decreasing; "
               + ", ".join(f"λ = {r:g}: {_f(v[th == THETA0][0] if (th == THETA0).any() else None)}"
                           f" at 20°, {_f(v[-1])} at {th[-1]:g}°" for r, v in pf.items())
               + ".")
        if len(rates) > 1:
            ok = [bool(np.all(np.diff([pf[r][i] for r in rates]) >= 0))
                  for i in range(len(th)) if all(np.isfinite(pf[r][i]) for r in rates)]
            txt += (f" Non-decreasing in λ at {sum(ok)} of {len(ok)} θ values "
                    f"(P2: grows with λ).")
        fa = {r: np.asarray(curve_for(res, SIGMA0, r)["false"])[o] for r in rates}  # type: ignore[index]
        tr = {r: np.asarray(curve_for(res, SIGMA0, r)["tracks"])[o] for r in rates}  # type: ignore[index]
        mono = [r for r in rates if np.all(np.diff(fa[r]) >= 0)]
        txt += (f" The number of false tracks is non-decreasing in θ for "
                f"{len(mono)} of {len(rates)} λ values.")
        if (th == THETA0).any():
            i20 = int(np.flatnonzero(th == THETA0)[0])
            grow = []
            for r in rates:
                t20, tmax = tr[r][i20] - fa[r][i20], tr[r][-1] - fa[r][-1]
                if fa[r][i20] > 0 and t20 > 0:
                    grow.append(f"λ = {r:g}: false ×{fa[r][-1] / fa[r][i20]:.2f}, "
                                f"true ×{tmax / t20:.2f}")
            if grow:
                txt += (" From 20° to the largest θ (counts, true tracks including "
                        "duplicates of one target): " + "; ".join(grow) + ". p_false is a "
                        "ratio: where a wider θ adds true tracks faster than false ones, it "
                        "falls although the false tracks grow.")
        out.append(txt)
    nm = sum(c["non_monotone_windows"] for c in res["curves"])
    nw = sum(c["n_windows"] for c in res["curves"])
    out.append(f"**Track count against θ.** In {nm} of {nw} windows the number of "
               f"modified-logic tracks decreased somewhere as θ grew (a miss branch "
               f"vanishes when a plot enters the gate, or a new 4-plot track removes "
               f"its 3-plot sub-tracks); elsewhere it is non-decreasing.")
    cl, me = res["clustering"], res["methods"]
    r1 = _speed_ratio(cl, "random", "adaptive", "t_scan")
    out.append(f"**Clustering (Fig. 2, Table 1).** k_correct_rate: adaptive "
               f"{_f(cl['adaptive']['k_correct_rate'])}, random start "
               f"{_f(cl['random']['k_correct_rate'])} (P2: adaptive finds all 10 targets, "
               f"random start fails). Time ratio K-means / adaptive: ours "
               f"{_f(r1, 2)}, P2 {PAPER_T_CLUSTER['random'] / PAPER_T_CLUSTER['adaptive']:.2f}"
               f". Ours runs the adaptive seeding plus a K-means refinement and the "
               f"one-plot-per-radar repair, so it is not cheaper than one K-means run.")
    rh = _speed_ratio(me, "hough", "logic", "t_window")
    rmh = _speed_ratio(me, "modified-hough", "logic", "t_window")
    rml = _speed_ratio(me, "modified-logic", "logic", "t_window")
    ours_order = sorted(INITIATORS, key=lambda m: me[m]["t_window"] or math.inf)
    paper_order = sorted(INITIATORS, key=lambda m: PAPER_T_INIT[m])
    out.append(f"**Initiation speed (Table 2).** Ratios to the 3/4 logic — modified logic: "
               f"ours {_f(rml, 2)}, P2 {0.18 / 0.17:.2f}; Hough: ours {_f(rh, 1)}, "
               f"P2 {114.5 / 0.17:.0f}; modified Hough: ours {_f(rmh, 1)}, "
               f"P2 {7.29 / 0.17:.0f}. Fastest to slowest, ours: "
               f"{' < '.join(METHOD_LABELS[m] for m in ours_order)}; P2: "
               f"{' < '.join(METHOD_LABELS[m] for m in paper_order)}. Our Hough votes with "
               f"array operations and counts distinct scans per cell, so it is not hundreds "
               f"of times slower than the logic; the absolute times (ms against P2's s) "
               f"reflect machine and implementation, not the algorithms.")
    ranks = {m: (me[m]["p_true"], me[m]["p_false"]) for m in INITIATORS}
    out.append("**Methods (Figs. 12–15)** at θ = 20°: "
               + "; ".join(f"{METHOD_LABELS[m]} p_true {_f(a)}, p_false {_f(b)}"
                           for m, (a, b) in ranks.items())
               + ". P2: modified logic and modified Hough give the true tracks with the "
               "fewest false ones; plain Hough fails.")
    return out


def report_markdown(res: Mapping[str, Any], runs: int, seed: int,
                    wall: float | None) -> str:
    lines = [
        "# Reproduction of P2 (adaptive K-means fusion + modified logic initiation)",
        "",
        f"`mhtrack reproduce p2 --runs {runs} --seed {seed}`: `multiradar` preset (3 polar "
        f"radars, 10 targets at 200 m/s, σθ = 0.3°), λ = clutter plots per radar per scan, "
        f"adaptive K-means fusion, sliding windows of 4 scans (7 per run), gate 300 m, "
        f"velocity gate 50–400 m/s. Run r uses seed `run_seeds({seed}, r + 1)[r]` for every "
        f"θ and method. P2 uses 1000 runs per point.",
        "",
        "Definitions (docs/initiation.md §3): p_true = initiable targets (seen in ≥ 3 "
        "scans of a window) with a true track / initiable targets; p_false = false tracks "
        "/ initiated tracks.",
        "",
    ]
    if wall is not None:
        lines += [f"Wall time of the jobs computed in this invocation: {wall:.1f} s.", ""]
    lines += ["## Figures", "",
              f"![P2 Fig. 3]({FIGURES['fig3']})", "",
              f"![P2 Fig. 4]({FIGURES['fig4']})", "",
              f"![P2 Fig. 2]({FIGURES['fig2']})", "",
              f"![P2 Figs. 12–15]({FIGURES['fig12_15']})", "",
              "## Where and why we differ from P2", ""]
    lines += [f"* {t}" for t in comparison_text(res)]
    lines += ["", tables_markdown(res).replace("# P2 Tables", "## P2 Tables", 1)
              .replace("\n## Table", "\n### Table"), ""]
    return "\n".join(lines)


# ---------------------------------------------------------------------- entry point
@dataclass
class P2Reproduction:
    out_dir: Path
    results: dict[str, Any]
    computed: int
    skipped: int
    errors: dict[str, str] = field(default_factory=dict)
    wall_seconds: float = 0.0

    @property
    def paths(self) -> list[Path]:
        return [self.out_dir / f for f in (*FIGURES.values(), TABLES_FILE, REPORT_FILE,
                                           RESULTS_FILE, JOBS_DIR)]


def _jsonable(o: Any) -> Any:
    if isinstance(o, dict):
        return {k: _jsonable(v) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [_jsonable(v) for v in o]
    if isinstance(o, float) and not math.isfinite(o):
        return None
    return o


def reproduce_p2(out_dir: str | os.PathLike[str], runs: int = 10, seed: int = 0, *,
                 thetas: Sequence[float] | None = None, sigmas: Sequence[float] | None = None,
                 rates: Sequence[float] | None = None, executor: str = "local",
                 workers: int | None = None, scheduler: Any = None, progress: bool = False,
                 chunk: int = CHUNK) -> P2Reproduction:
    """Run (or resume) the P2 study into ``out_dir/jobs/`` and write the figures, tables,
    report and ``results.json`` (module docstring). ``thetas`` (deg), ``sigmas`` (m) and
    ``rates`` default to P2's grids."""
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    if seed < 0:
        raise ValueError(f"seed must be >= 0, got {seed}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    thetas = list(THETAS_DEG if thetas is None else thetas)
    if not all(0 <= x <= 180 for x in thetas):
        raise ValueError("thetas must be in [0, 180] degrees")
    jobs = make_jobs(runs, seed, thetas, SIGMAS if sigmas is None else sigmas,
                     RATES if rates is None else rates, chunk)
    t0 = time.perf_counter()
    results, errors, computed = run_jobs(jobs, out / JOBS_DIR, executor=executor,
                                         workers=workers, scheduler=scheduler,
                                         progress=progress)
    wall = time.perf_counter() - t0
    res = aggregate(jobs, results, thetas)
    res.update(runs=runs, seed=seed, paper={"t_cluster": PAPER_T_CLUSTER,
                                            "t_init": PAPER_T_INIT,
                                            "complexity": PAPER_COMPLEXITY},
               jobs={"total": len(jobs), "computed": computed, "failed": sorted(errors)})
    res = _jsonable(res)
    atomic_write(out / RESULTS_FILE, json.dumps(res, indent=1) + "\n")
    sig = sorted({c["sigma_range"] for c in res["curves"] if c["clutter_rate"] == RATE0})
    rat = sorted({c["clutter_rate"] for c in res["curves"] if c["sigma_range"] == SIGMA0})
    _curve_figure(res, "p_true", [(s, RATE0) for s in sig], lambda s, r: f"σr = {s:g} m",
                  f"P2 Fig. 3: p_true of modified 3/4 logic, λ = {RATE0:g} ({runs} runs)",
                  out / FIGURES["fig3"])
    _curve_figure(res, "p_false", [(SIGMA0, r) for r in rat], lambda s, r: f"λ = {r:g}",
                  f"P2 Fig. 4: p_false of modified 3/4 logic, σr = {SIGMA0:g} m "
                  f"({runs} runs)", out / FIGURES["fig4"])
    for fn, name in ((_clustering_figure, "fig2"), (_tracks_figure, "fig12_15")):
        try:
            fn(seed, out / FIGURES[name])
        except Exception:  # a figure must not lose the study
            atomic_write(out / f"{FIGURES[name]}.error.txt", traceback.format_exc())
    atomic_write(out / TABLES_FILE, tables_markdown(res))
    atomic_write(out / REPORT_FILE, report_markdown(res, runs, seed,
                                                     wall if computed else None))
    return P2Reproduction(out, res, computed, len(jobs) - computed, errors, wall)
