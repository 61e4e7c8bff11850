"""The jobs of the P2 (Gong, Dai & Ma 2013, multi-radar track initiation) study and their
runner.

:func:`~mhtrack.experiments.p2.study.reproduce_p2` runs (or resumes) three kinds of jobs,
each a chunk of runs, through a local process pool or a Dask scheduler
(:func:`run_jobs`), saving each job's counts to ``DIR/jobs/<name>.json`` (atomically) as it
finishes; a rerun skips finished jobs whose stored parameters match:

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

Job functions are top-level functions of plain data (picklable for the pool and Dask).
A job's ``job_hash`` and its file hold only the job's parameters, no module path.
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.experiments.montecarlo import atomic_write, execute
from mhtrack.experiments.p2.constants import CHUNK, LOGIC_PARAMS, RATE0, SIGMA0, THETA0
from mhtrack.initiation import INITIATORS, Window, make_initiator
from mhtrack.initiation.logic import sweep_modified_logic
from mhtrack.initiation.runs import fuse, fused_scans, n_targets_seen, run_seeds
from mhtrack.initiation.window import sliding_windows
from mhtrack.metrics.initiation import initiable_targets, track_targets
from mhtrack.scenario import Scenario, preset, simulate


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
