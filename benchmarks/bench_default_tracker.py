"""Which clutter estimator should the real-radar default tracker use? Paired runs of
``mht-agmm`` (the default), ``mht-mapgmm`` and ``mht-gmm`` on the rotating-radar presets
``opensky-radars`` and ``radars-clutter``, each without a clutter scene and with each named
scene of :mod:`mhtrack.scenario.scenes` — the jobs of ``mhtrack reproduce clutter-scenes``
(:func:`mhtrack.experiments.clutter_scenes.run_job`: the tracker ``mhtrack run`` builds,
scored in the history and online views), run-major so that a study cut short still pairs.

    python benchmarks/bench_default_tracker.py --runs 10 --out DIR \\
        [--scans radars-clutter=150 --scans opensky-radars=60] [--method agmm ...]

Writes ``DIR/jobs/`` (resumable) and prints, per preset (pooled over its scene settings)
and per setting, the paired differences ``A − B`` with their 95 % t intervals
(:func:`mhtrack.metrics.paired.compare_paired`). ``t_cpu``: the tracker's CPU time
over the run (``time.thread_time`` around the tracking, the clutter-error probe's own
removed).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from mhtrack.experiments.clutter_scenes import STORE, run_job
from mhtrack.experiments.jobs import SPACED, Job, JobStore, run_jobs, run_seed
from mhtrack.metrics.paired import compare_paired, paired_by_run
from mhtrack.scenario import preset
from mhtrack.scenario.scenes import SCENES, with_clutter_scene

PRESETS = ("radars-clutter", "opensky-radars")
SETTINGS = ("none", *SCENES)
#: Metric key → higher is better.
METRICS = {
    "ospa_history": False, "ospa_online": False,
    "false_tracks_history": False, "false_tracks_online": False,
    "ids_history": False, "ids_online": False,
    "fragmentations_history": False, "fragmentations_online": False,
    "id_switches_history": False, "id_switches_online": False,
    "coverage_history": True, "coverage_online": True,
    "hota_history": True, "hota_online": True,
    "iae_mean": False, "t_cpu": False,
}
PAIRS = (("mapgmm", "agmm"), ("gmm", "agmm"), ("mapgmm", "gmm"))


def jobs(runs: int, seed: int, methods: tuple[str, ...], scans: dict[str, int],
         presets: tuple[str, ...] = PRESETS, settings: tuple[str, ...] = SETTINGS
         ) -> list[Job]:
    """Run-major: run 0 of every preset, setting and method, then run 1, …"""
    dicts = {}
    for p in presets:
        base = preset(p, scans=scans.get(p))
        for s in settings:
            dicts[p, s] = (base if s == "none" else with_clutter_scene(base, s)).to_dict()
    out = []
    for i in range(runs):
        for (p, s), d in dicts.items():
            for m in methods:
                params = {"cutoff": 500.0, "order": 2.0, "resolution": 100, "scenario": d,
                          "preset": p, "scene": s, "method": m, "run": i,
                          "seed": run_seed(seed, i, "spawn"), "params": {}}
                out.append(Job.of(f"{p}/{s}/{m}/run-{i}", params, SPACED))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--method", action="append", default=None)
    ap.add_argument("--scans", action="append", default=[], help="PRESET=N")
    ap.add_argument("--report-only", action="store_true", help="only read DIR/jobs")
    ap.add_argument("--preset", action="append", choices=PRESETS, default=None,
                    help="only this preset (repeat) [both]")
    ap.add_argument("--setting", action="append", choices=SETTINGS, default=None,
                    help="only this scene setting (repeat) [all]")
    a = ap.parse_args()
    methods = tuple(a.method or ("agmm", "mapgmm", "gmm"))
    scans = {k: int(v) for k, v in (x.split("=") for x in a.scans)}
    presets, settings = tuple(a.preset or PRESETS), tuple(a.setting or SETTINGS)
    js = jobs(a.runs, a.seed, methods, scans, presets, settings)
    store = JobStore(a.out / "jobs", STORE)
    if not a.report_only:
        run_jobs(js, run_job, store, workers=1, progress=True, desc="default-tracker")
    recs: dict[tuple[str, str, str], list[dict]] = {}
    for j in js:
        if store.is_done(j):
            pr = j.params
            recs.setdefault((pr["preset"], pr["scene"], pr["method"]), []).append(store.load(j))
    for p in presets:
        groups = [("pooled", settings), *((s, (s,)) for s in settings)]
        for label, settings in groups:
            pooled: dict[str, list[dict]] = {}
            for k, s in enumerate(settings):
                for m in methods:
                    pooled.setdefault(m, []).extend(
                        {**r, "run": k * 10**6 + int(r["run"])} for r in recs.get((p, s, m), []))
            print(f"\n## {p} / {label}")
            for m in methods:
                r = pooled[m]
                if r:
                    print(f"  {m}: n={len(r)} " + " ".join(
                        f"{k}={sum(float(x[k]) for x in r) / len(r):.4g}" for k in METRICS))
            for a_, b_ in PAIRS:
                if not (pooled.get(a_) and pooled.get(b_)):
                    continue
                for k, hb in METRICS.items():
                    va, vb, _ = paired_by_run(pooled[a_], pooled[b_], k)
                    c = compare_paired(va, vb, metric=k, name_a=a_, name_b=b_,
                                       higher_better=hb)
                    print(f"  {a_}-{b_} {k}: n={c.n} {c.mean_diff:+.4g} "
                          f"[{c.ci_low:+.4g}, {c.ci_high:+.4g}] {c.verdict}")


if __name__ == "__main__":
    main()
