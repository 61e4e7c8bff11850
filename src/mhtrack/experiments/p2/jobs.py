"""The jobs of the P2 (Gong, Dai & Ma 2013, multi-radar track initiation) study.

:func:`~mhtrack.experiments.p2.study.reproduce_p2` runs (or resumes) three kinds of jobs,
each a chunk of runs, with the job runner :func:`mhtrack.experiments.jobs.run_jobs`
(this process, local processes or Dask), which stores each job's counts in
``DIR/jobs/<name>.json`` (:data:`STORE_FORMAT`) as it finishes; a rerun skips finished
jobs whose stored hash matches:

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

Run ``r`` simulates with ``run_seed(seed, r, "words")`` (:mod:`mhtrack.experiments.jobs.seeds`;
the seed ``mhtrack initiate --seed S`` uses for its run ``r``): it depends on ``seed`` and
``r`` only, so every θ and every method sees the same plots. ``λ`` is the clutter rate per
radar per scan (3 radars; ``clutter_per="scan"``: λ/3 per radar).

A job's ``settings`` (absent: ``"best"``) and ``clutter_per`` (absent: ``"radar"``)
select the fusion and initiator options (:data:`~mhtrack.experiments.p2.constants.SETTINGS`);
the keys are stored only when not the default, so the default jobs keep their hashes.

Job functions are top-level functions of plain data (picklable for the pool and Dask).
A job's key is its ``name``; its hash (JSON with ``json.dumps``' default separators, as
the study directories written so far) and its file hold only the job's parameters.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from mhtrack.experiments.initiation_runs import (
    FusedRun,
    fuse,
    initiators,
    n_targets_seen,
    simulate_and_fuse,
    targets_seen,
)
from mhtrack.experiments.jobs import SPACED, Job, JsonRecords, run_seed
from mhtrack.experiments.p2.constants import (
    CHUNK,
    FUSION_PARAMS,
    INITIATOR_PARAMS,
    LOGIC_PARAMS,
    RATE0,
    SIGMA0,
    THETA0,
)
from mhtrack.initiation import Window
from mhtrack.initiation.logic import sweep_modified_logic
from mhtrack.metrics.initiation import initiable_targets, track_targets
from mhtrack.names import INITIATORS
from mhtrack.scenario import Scenario, preset, simulate

#: How a job's counts are stored: ``DIR/jobs/<name>.json``.
STORE_FORMAT = JsonRecords()


def p2_scenario(sigma_range: float = SIGMA0, clutter_rate: float = RATE0) -> Scenario:
    """``multiradar`` with every radar's range σ set to ``sigma_range`` (m) and
    ``clutter_rate`` clutter plots per radar per scan."""
    return preset("multiradar", clutter_rate=clutter_rate, sigma_range=sigma_range)


def job_scenario(job: Mapping[str, Any]) -> Scenario:
    """The job's scenario; ``clutter_per="scan"`` spreads λ over the radars."""
    sc = p2_scenario(job["sigma"], job["rate"])
    if job.get("clutter_per", "radar") == "scan" and job["rate"]:
        sc = p2_scenario(job["sigma"], job["rate"] / len(sc.sensors))
    return sc


def fused_run(sc: Scenario, seed: int, settings: str = "best") -> FusedRun:
    """Simulate and fuse one run with the fusion options of ``settings``."""
    return simulate_and_fuse(sc, seed, params=FUSION_PARAMS[settings])


def _initiable(raw_win: Sequence[Any]) -> np.ndarray:
    return initiable_targets(*targets_seen(raw_win))


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
    sc = job_scenario(job)
    settings = job.get("settings", "best")
    thetas = job["thetas"]
    n = len(thetas)
    found, false, tracks = np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, np.int64)
    n_targets = n_windows = non_monotone = 0
    t0 = time.perf_counter()
    for r in range(job["start"], job["stop"]):
        for raw_win, win in fused_run(sc, run_seed(job["seed"], r, "words"), settings
                                      ).windows(4):
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
    sc = job_scenario(job)
    fparams = FUSION_PARAMS[job.get("settings", "best")]
    out: dict[str, Any] = {m: {"k_correct": 0, "seconds": 0.0, "clusters": 0}
                           for m in ("adaptive", "random")}
    n_scans = 0
    for r in range(job["start"], job["stop"]):
        rs = run_seed(job["seed"], r, "words")
        for scan in simulate(sc, rs).plots.scans():
            n_scans += 1
            k_true = n_targets_seen(scan)
            for m in ("adaptive", "random"):
                t0 = time.perf_counter()
                f = fuse(scan, m, run_seed=rs, **(fparams if m == "adaptive" else {}))
                out[m]["seconds"] += time.perf_counter() - t0
                out[m]["k_correct"] += int(f.n_clusters == k_true)
                out[m]["clusters"] += int(f.n_clusters)
    out["n_scans"] = n_scans
    return out


def _initiators(region: tuple[float, ...], settings: str = "best") -> dict[str, Any]:
    """The four initiators with the study's settings (those of ``mhtrack initiate``, plus
    :data:`~mhtrack.experiments.p2.constants.INITIATOR_PARAMS` of ``settings``)."""
    return initiators(region, theta_deg=THETA0, **LOGIC_PARAMS,
                      extra=INITIATOR_PARAMS[settings])


def methods_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """One ``methods`` job: the four initiators at θ = 20° (time per window: stacking
    the fused window + initiating, as ``mhtrack initiate``)."""
    sc = job_scenario(job)
    settings = job.get("settings", "best")
    inits = _initiators(sc.region.as_tuple(), settings)
    out: dict[str, Any] = {m: {"found": 0, "false": 0, "tracks": 0, "seconds": 0.0}
                           for m in INITIATORS}
    n_targets = n_windows = n_scans = 0
    fusion_seconds = 0.0
    for r in range(job["start"], job["stop"]):
        run = fused_run(sc, run_seed(job["seed"], r, "words"), settings)
        before = {m: (out[m]["found"], out[m]["false"], out[m]["tracks"]) for m in inits}
        t_before, w_before = n_targets, n_windows
        fusion_seconds += sum(run.fusion_seconds)
        n_scans += len(run.fusion_seconds)
        for raw_win, win in run.windows(4):
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
        for m in inits:  # this run's counts, for paired comparisons
            out[m].setdefault("per_run", []).append(
                [out[m][k] - b for k, b in zip(("found", "false", "tracks"), before[m],
                                                strict=True)]
                + [n_targets - t_before, n_windows - w_before])
    out.update(n_targets=n_targets, n_windows=n_windows, n_scans=n_scans,
               fusion_seconds=fusion_seconds)
    return out


JOB_FUNCTIONS: dict[str, Callable[[Mapping[str, Any]], dict[str, Any]]] = {
    "grid": grid_job, "clustering": clustering_job, "methods": methods_job}


def run_job(job: Mapping[str, Any]) -> dict[str, Any]:
    """Run one job (top level, picklable: what the pool / Dask workers call)."""
    return JOB_FUNCTIONS[job["kind"]](job)


def _count(v: object, field: str) -> None:
    if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= 2**53:
        raise ValueError(f"{field}: expected a count (an integer in [0, 2^53]), got {v!r}")


def _seconds(v: object, field: str) -> None:
    if isinstance(v, bool) or not isinstance(v, int | float) or not 0 <= v <= 1e12:
        raise ValueError(f"{field}: expected seconds (a number in [0, 1e12]), got {v!r}")


def _table(record: Mapping[str, Any], field: str, counts: Sequence[str],
           seconds: Sequence[str]) -> None:
    sub = record.get(field) if field else record
    if not isinstance(sub, Mapping):
        raise ValueError(f"{field}: expected an object, got {type(sub).__name__}")
    at = f"{field}." if field else ""
    for k in counts:
        _count(sub.get(k), at + k)
    for k in seconds:
        _seconds(sub.get(k), at + k)


def check_record(job: Job, record: Mapping[str, Any]) -> None:
    """A stored record has the shape its job's function returns (checked before
    :func:`~mhtrack.experiments.p2.aggregate.aggregate` reads it); raises
    ``ValueError("<field>: <problem>")``."""
    kind = job.params["kind"]
    if kind == "grid":
        n = len(job.params["thetas"])
        for k in ("found", "false", "tracks"):
            v = record.get(k)
            if not isinstance(v, list) or len(v) != n:
                got = f"a list of {len(v)}" if isinstance(v, list) else type(v).__name__
                raise ValueError(f"{k}: expected a list of {n} counts (one per θ), got {got}")
            for i, x in enumerate(v):
                _count(x, f"{k}[{i}]")
        _table(record, "", ("n_targets", "n_windows", "non_monotone_windows"), ("seconds",))
    elif kind == "clustering":
        for m in ("adaptive", "random"):
            _table(record, m, ("k_correct", "clusters"), ("seconds",))
        _count(record.get("n_scans"), "n_scans")
    else:
        for m in INITIATORS:
            _table(record, m, ("found", "false", "tracks"), ("seconds",))
        _table(record, "", ("n_targets", "n_windows", "n_scans"), ("fusion_seconds",))


def make_jobs(runs: int, seed: int, thetas: Sequence[float], sigmas: Sequence[float],
              rates: Sequence[float], chunk: int = CHUNK, *, settings: str = "best",
              clutter_per: str = "radar") -> list[Job]:
    """All jobs of a study (module docstring); each keyed by its unique ``name``."""
    opts: dict[str, str] = {}
    if settings != "best":
        opts["settings"] = settings
    if clutter_per != "radar":
        opts["clutter_per"] = clutter_per
    points = [(float(s), RATE0) for s in sigmas] + [(SIGMA0, float(r)) for r in rates]
    points = list(dict.fromkeys(points))
    chunks = [(a, min(a + chunk, runs)) for a in range(0, runs, chunk)]
    jobs = []

    def add(kind: str, name: str, sigma: float, rate: float, a: int, b: int,
            **extra: Any) -> None:
        params: dict[str, Any] = {"kind": kind, "name": f"{name}-r{a}-{b}", "sigma": sigma,
                                  "rate": rate, "start": a, "stop": b, "seed": int(seed),
                                  **extra, **opts}
        jobs.append(Job.of(params["name"], params, SPACED))

    for a, b in chunks:
        for s, r in points:
            add("grid", f"grid-s{s:g}-l{r:g}", s, r, a, b, thetas=[float(x) for x in thetas])
        add("clustering", "clustering-s20-l0", SIGMA0, 0.0, a, b)
        add("methods", f"methods-s{SIGMA0:g}-l{RATE0:g}", SIGMA0, RATE0, a, b)
    return jobs
