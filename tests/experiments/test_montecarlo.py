"""Monte-Carlo runner: determinism across executors, resume, failures, files."""

import json
import math
import os
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from mhtrack.experiments import (
    MonteCarloSpec,
    SpecMismatchError,
    load_results,
    run_job,
    run_montecarlo,
)
from mhtrack.experiments.montecarlo import MonteCarloResult
from mhtrack.reports.montecarlo import summary_markdown, write_montecarlo_report
from mhtrack.scenario import preset


def run_path(out, tracker, run, suffix=".parquet"):
    """Where a run's file lives (the documented layout, written out independently)."""
    return Path(out) / "runs" / tracker / f"run-{run}{suffix}"

TRACKERS = ("mht", "mht-gmm", "mht-agmm")


@pytest.fixture(scope="module")
def spec() -> MonteCarloSpec:
    sc = preset("crossing", clutter="uniform", clutter_rate=5, scans=12)
    return MonteCarloSpec(sc, TRACKERS, runs=2, seed=7)


@pytest.fixture(scope="module")
def inline(spec, tmp_path_factory):
    """The reference study, run in this process."""
    out = tmp_path_factory.mktemp("mc-inline")
    return run_montecarlo(spec, out, workers=1)


def comparable(result) -> dict:
    """Every record with the wall-clock fields removed and NaN made comparable."""
    def clean(v):
        return None if isinstance(v, float) and math.isnan(v) else v

    return {t: [{k: clean(v) for k, v in r.items() if k != "t_avg"} for r in recs]
            for t, recs in result.records.items()}


def fail_mht_gmm_run_1(job):
    """A job function that fails for one job (top level, so it pickles to a fork)."""
    if job["tracker"] == "mht-gmm" and job["run"] == 1:
        raise RuntimeError("boom in mht-gmm run 1")
    return run_job(job)


def test_job_hash_of_an_old_study_is_unchanged():
    """Pinned hash of a job as the code before the job runner computed it: an old study
    directory resumes without recomputing anything."""
    job = MonteCarloSpec({"name": "tiny"}, ("mht",), runs=2, seed=3).job("mht", 1)
    assert job.hash == "0c59fb0fb776a4066ed4fccb29a1b6f6f8d13d604ee3ddbe3ea002ae98316a2d"
    assert job.key == "mht/run-1"


def test_trackers_share_a_run_seed_and_runs_differ(inline):
    seeds = {t: [r["seed"] for r in inline.records[t]] for t in TRACKERS}
    assert seeds["mht"] == seeds["mht-gmm"] == seeds["mht-agmm"]
    assert len(set(seeds["mht"])) == 2
    assert all(r["base_seed"] == 7 for recs in inline.records.values() for r in recs)


def test_inline_run_writes_one_file_per_job(spec, inline):
    out = inline.out_dir
    assert inline.ok and inline.computed == 6 and inline.skipped == 0
    stored = json.loads((out / "montecarlo.json").read_text())
    assert stored["trackers"] == list(TRACKERS) and stored["runs"] == 2
    assert stored["seed"] == 7 and stored["scenario"]["name"] == "crossing"
    for t in TRACKERS:
        for i in range(2):
            row = pq.read_table(run_path(out, t, i)).to_pylist()
            assert len(row) == 1
            row = row[0]
            assert row["tracker"] == t and row["run"] == i and row["scenario"] == "crossing"
            assert row["seed"] == inline.records["mht"][i]["seed"]
            assert len(row["ospa"]) == len(row["scans"]) == len(row["cardinality"]) == 12
            assert {"ospa_mean", "mota", "t_avg", "cardinality_true"} <= set(row)
    # every tracker sees the same plots in run i: same truth count
    for i in range(2):
        n_truth = {inline.records[t][i]["n_truth"] for t in TRACKERS}
        assert len(n_truth) == 1


def test_two_workers_give_the_same_runs(spec, inline, tmp_path):
    pooled = run_montecarlo(spec, tmp_path, workers=2)
    assert pooled.ok and pooled.computed == 6
    assert comparable(pooled) == comparable(inline)


def test_dask_cluster_gives_the_same_runs(spec, inline, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        result = run_montecarlo(spec, tmp_path, executor="dask",
                                scheduler=cluster.scheduler_address)
    assert result.ok and result.computed == 6
    assert comparable(result) == comparable(inline)


def test_resume_recomputes_only_the_missing_run(spec, tmp_path):
    calls = []

    def counting(job):
        calls.append((job["tracker"], job["run"]))
        return run_job(job)

    first = run_montecarlo(spec, tmp_path, workers=1, job_function=counting)
    assert len(calls) == 6 and first.ok
    mtimes = {p: p.stat().st_mtime_ns for p in tmp_path.glob("runs/*/*.parquet")}
    run_path(tmp_path, "mht-agmm", 1).unlink()
    calls.clear()
    again = run_montecarlo(spec, tmp_path, workers=1, job_function=counting)
    assert calls == [("mht-agmm", 1)]
    assert again.computed == 1 and again.skipped == 5 and again.ok
    for p, t in mtimes.items():
        if p != run_path(tmp_path, "mht-agmm", 1):
            assert p.stat().st_mtime_ns == t
    assert comparable(again) == comparable(first)
    # nothing left to do: a third call computes nothing
    calls.clear()
    assert run_montecarlo(spec, tmp_path, workers=1, job_function=counting).computed == 0
    assert calls == []


def test_more_runs_extend_a_study(spec, inline, tmp_path):
    small = MonteCarloSpec(spec.scenario, ("mht",), runs=1, seed=7)
    run_montecarlo(small, tmp_path, workers=1)
    bigger = MonteCarloSpec(spec.scenario, ("mht",), runs=2, seed=7)
    r = run_montecarlo(bigger, tmp_path, workers=1)
    assert r.computed == 1 and r.skipped == 1
    assert comparable(r)["mht"] == comparable(inline)["mht"]


def test_other_parameters_in_the_directory_are_refused(spec, tmp_path):
    one = MonteCarloSpec(spec.scenario, ("mht",), runs=1, seed=7)
    run_montecarlo(one, tmp_path, workers=1)
    with pytest.raises(SpecMismatchError, match="seed"):
        run_montecarlo(MonteCarloSpec(spec.scenario, ("mht",), runs=1, seed=8), tmp_path,
                       workers=1)
    with pytest.raises(SpecMismatchError, match="config"):
        run_montecarlo(MonteCarloSpec(spec.scenario, ("mht",), runs=1, seed=7,
                                      config={"n_scan": 2}), tmp_path, workers=1)
    # a run file of other parameters (spec file gone) is refused too
    (tmp_path / "montecarlo.json").unlink()
    with pytest.raises(SpecMismatchError, match="other parameters"):
        run_montecarlo(MonteCarloSpec(spec.scenario, ("mht",), runs=1, seed=8), tmp_path,
                       workers=1)


@pytest.mark.parametrize("workers", [1, 2])
def test_a_failing_job_is_recorded_and_the_others_complete(spec, inline, tmp_path, workers):
    r = run_montecarlo(spec, tmp_path, workers=workers, job_function=fail_mht_gmm_run_1)
    assert not r.ok
    assert set(r.failures["mht-gmm"]) == {1}
    err = run_path(tmp_path, "mht-gmm", 1, ".error.txt").read_text()
    assert "boom in mht-gmm run 1" in err and "Traceback" in err
    assert not run_path(tmp_path, "mht-gmm", 1).exists()
    assert [len(r.records[t]) for t in TRACKERS] == [2, 1, 2]
    s = r.summary()
    assert s["mht-gmm"]["failed"] == [1] and s["mht-gmm"]["n_runs"] == 1
    write_montecarlo_report(r)
    assert "* mht-gmm run 1: see `runs/mht-gmm/run-1.error.txt`" in (
        tmp_path / "summary.md").read_text()
    # a rerun retries the failed job only and clears its error file
    fixed = run_montecarlo(spec, tmp_path, workers=1)
    assert fixed.ok and fixed.computed == 1
    assert not run_path(tmp_path, "mht-gmm", 1, ".error.txt").exists()
    assert comparable(fixed) == comparable(inline)


def test_summary_equals_numpy_on_the_stored_files(spec, inline):
    """Means and population stds of the summary equal numpy's over the Parquet files read
    back with pyarrow (not through the runner's reader)."""
    s = inline.summary()
    assert list(s) == list(TRACKERS)
    for t in TRACKERS:
        rows = [pq.read_table(run_path(inline.out_dir, t, i)).to_pylist()[0] for i in range(2)]
        for k in ("ospa_mean", "mota", "gospa_mean", "t_avg"):
            vals = np.array([r[k] for r in rows], float)
            assert s[t][k] == np.mean(vals)
            assert s[t]["std"][k] == np.std(vals)
        ps = s[t]["per_scan"]
        assert ps["scans"] == list(range(1, 13))
        ospa = np.array([r["ospa"] for r in rows])
        np.testing.assert_array_equal(ps["ospa"], ospa.mean(axis=0))
        np.testing.assert_array_equal(ps["ospa_std"], ospa.std(axis=0))
        assert len(ps["cardinality"]) == len(ps["cardinality_std"]) == 12
    write_montecarlo_report(inline)
    md = (inline.out_dir / "summary.md").read_text()
    assert "| ospa_mean |" in md and " ± " in md
    assert (inline.out_dir / "ospa_cardinality.png").read_bytes()[:4] == b"\x89PNG"
    loaded = load_results(inline.out_dir)
    assert comparable(loaded) == comparable(inline)


def test_hand_worked_summary(tmp_path):
    """Three runs: a metric 1, 2, NaN → mean 1.5, std 0.5 (NaN ignored); per scan, a scan
    seen in one run only counts that run."""
    spec = MonteCarloSpec({"name": "tiny"}, ("mht",), runs=3, seed=0)
    recs = [
        {"run": 0, "seed": 1, "m": 1.0, "scans": [1, 2], "ospa": [10.0, 20.0],
         "gospa": [0.0, 0.0], "cardinality": [1, 2], "cardinality_true": [1, 1]},
        {"run": 1, "seed": 2, "m": 2.0, "scans": [1, 2, 3], "ospa": [30.0, 40.0, 50.0],
         "gospa": [0.0, 0.0, 0.0], "cardinality": [3, 2, 1], "cardinality_true": [1, 1, 1]},
        {"run": 2, "seed": 3, "m": math.nan, "scans": [], "ospa": [], "gospa": [],
         "cardinality": [], "cardinality_true": []},
    ]
    res = MonteCarloResult(spec, tmp_path, {"mht": recs}, {"mht": {}})
    s = res.summary()["mht"]
    assert res.metric_keys() == ["m"]
    assert (s["m"], s["std"]["m"], s["n_runs"]) == (1.5, 0.5, 3)
    ps = s["per_scan"]
    assert ps["scans"] == [1, 2, 3]
    assert ps["ospa"] == [20.0, 30.0, 50.0] and ps["ospa_std"] == [10.0, 10.0, 0.0]
    assert ps["cardinality"] == [2.0, 2.0, 1.0] and ps["cardinality_std"] == [1.0, 0.0, 0.0]
    md = summary_markdown(res)
    assert "| m | 1.5 ± 0.5 |" in md and "| runs ok | 3 |" in md


def test_spec_validation(spec):
    with pytest.raises(ValueError, match="unknown tracker"):
        MonteCarloSpec(spec.scenario, ("nope",), runs=1)
    with pytest.raises(ValueError, match="runs"):
        MonteCarloSpec(spec.scenario, ("mht",), runs=0)
    with pytest.raises(ValueError, match="MHTConfig"):
        MonteCarloSpec(spec.scenario, ("mht",), config={"bogus": 1})
    with pytest.raises(ValueError, match="set by the runner"):
        MonteCarloSpec(spec.scenario, ("mht",), run_kwargs={"seed": 1})
    assert MonteCarloSpec.from_dict(spec.to_dict()) == spec


def test_run_kwargs_are_forwarded_verbatim(spec, tmp_path):
    job = MonteCarloSpec(spec.scenario, ("mht",), runs=1, run_kwargs={"cutoff": 100.0}).job(
        "mht", 0)
    assert run_job(job.as_dict())["cutoff"] == 100.0


def test_no_stray_temporary_files(inline):
    names = [p.name for p in Path(inline.out_dir).rglob("*")]
    assert not [n for n in names if n.startswith(".")]
    assert os.path.isdir(inline.out_dir / "runs" / "mht")


def test_an_interruption_loses_no_finished_run(spec, inline, tmp_path):
    done = []

    def interrupted(job):
        if len(done) == 2:
            raise KeyboardInterrupt
        done.append(job)
        return run_job(job)

    with pytest.raises(KeyboardInterrupt):
        run_montecarlo(spec, tmp_path, workers=1, job_function=interrupted)
    assert len(list(tmp_path.glob("runs/*/*.parquet"))) == 2
    assert not list(tmp_path.rglob(".*"))
    resumed = run_montecarlo(spec, tmp_path, workers=1)
    assert resumed.computed == 4 and resumed.skipped == 2
    assert comparable(resumed) == comparable(inline)


def test_runs_with_caps_counts_runs_where_a_cap_acted(tmp_path):
    spec = MonteCarloSpec(preset("crossing", scans=5), ["mht"], 3, 0)
    recs = [{"caps": "{}"}, {"caps": '{"max_leaves": 4}'}, {"caps": '{"max_trees": 1}'}]
    res = MonteCarloResult(spec, tmp_path, {"mht": recs}, {"mht": {}})
    assert res.runs_with_caps() == {"mht": 2}


def test_unknown_run_keyword_is_refused_before_any_run(spec):
    with pytest.raises(ValueError, match=r"run_kwargs: unknown keyword.*foo"):
        MonteCarloSpec(spec.scenario, ("mht",), runs=1, seed=7, run_kwargs={"foo": 1})
