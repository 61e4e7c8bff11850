"""reproduce clutter-shift: jobs pair by run, the oracle's clutter error is 0, every
verdict matches its interval, and the report's sentences are the generator's."""

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from mhtrack.cli.reproduce_commands import reproduce
from mhtrack.experiments import clutter_shift as cs
from mhtrack.reports.clutter_shift import write_clutter_shift_report
from mhtrack.scenario import preset, simulate


def short():
    return preset("crossing-changing", scans=8)


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("cs")
    st = cs.clutter_shift(out, runs=3, seed=2, scenario=short(), resolution=40, workers=1)
    write_clutter_shift_report(st, short())
    return st


def test_runs_pair_and_files(study):
    assert not study.errors and study.computed == 12
    seeds = {m: [r["seed"] for r in recs] for m, recs in study.records.items()}
    assert len({tuple(v) for v in seeds.values()}) == 1  # same plots for every method
    for name in ("results.json", "report.md", "clutter_error.png"):
        assert (study.out_dir / name).is_file()


def test_oracle_has_no_clutter_error(study):
    for r in study.records["known"]:
        assert r["iae_mean"] == pytest.approx(0.0, abs=1e-12)
    for r in study.records["uniform"]:
        assert r["iae_mean"] > 0


def test_every_verdict_matches_its_interval(study):
    res = json.loads((study.out_dir / "results.json").read_text())
    assert len(res["paired"]) == len(cs.PAIRS) * len(cs.METRICS)
    for p in res["paired"]:
        lo, hi = p["ci_low"], p["ci_high"]
        if lo is None or math.isnan(lo) or lo <= 0 <= hi:
            assert p["verdict"] == "no detectable difference", p
        elif lo > 0:
            assert p["verdict"] == ("better" if p["higher_better"] else "worse"), p
        else:
            assert p["verdict"] == ("worse" if p["higher_better"] else "better"), p
        if p["verdict"] == "no detectable difference":
            assert f"no detectable difference at n = {p['n']}" in p["sentence"]
        else:
            assert f"{p['a']} is {p['verdict']} than {p['b']}" in p["sentence"]
    text = (study.out_dir / "report.md").read_text()
    for c in study.paired:
        assert c.sentence in text
    assert "## P1's claim on a clutter that changes" in text


def test_resume_computes_nothing(study):
    again = cs.clutter_shift(study.out_dir, runs=3, seed=2, scenario=short(), resolution=40,
                             workers=1)
    assert again.computed == 0 and again.skipped == 12
    assert [c.to_dict() for c in again.paired] == [c.to_dict() for c in study.paired]


def test_uniform_count_estimator():
    sim = simulate(short(), seed=1)
    est = cs.UniformCountClutter(area=64e6, window=2)
    counts = []
    for scan in sim.plots.scans():
        est.update(scan)
        counts.append(len(scan))
    want = np.mean(counts[-2:]) / 64e6
    assert est.intensity(np.zeros((3, 2))) == pytest.approx(np.full(3, want))


def test_cli(tmp_path, monkeypatch):
    monkeypatch.setattr(cs, "default_scenario", short)
    r = CliRunner().invoke(reproduce, ["clutter-shift", "--runs", "2", "--workers", "1",
                                       "--out", str(tmp_path), "--no-progress"])
    assert r.exit_code == 0, r.output
    assert "agmm vs gmm" in r.stdout
    assert (tmp_path / "report.md").is_file() and (tmp_path / "results.json").is_file()


def test_cli_rejects_bad_runs(tmp_path):
    r = CliRunner().invoke(reproduce, ["clutter-shift", "--runs", "0", "--out", str(tmp_path)])
    assert r.exit_code == 2


def test_ablation_cached_and_explained(tmp_path):
    from mhtrack.experiments.clutter_shift_ablation import VARIANTS, cached_ablation
    from mhtrack.reports.clutter_shift import analysis_text

    sc = preset("crossing-changing", scans=5)
    ab = cached_ablation(tmp_path, sc, runs=2, resolution=30)
    assert set(ab.iae) == set(VARIANTS) and all(len(v) == 2 for v in ab.iae.values())
    # the same study read back, not recomputed
    again = cached_ablation(tmp_path, sc, runs=2, resolution=30)
    assert [c.to_dict() for c in again.paired] == [c.to_dict() for c in ab.paired]
    # each comparison is the variant against the GMM, paired on the same runs
    for c in ab.paired:
        assert c.b == "gmm" and c.n == 2
        assert c.mean_diff == pytest.approx(np.mean(ab.iae[c.a]) - np.mean(ab.iae["gmm"]))
    text = analysis_text(ab)
    for c in ab.paired:
        assert c.sentence in text


def _timeless(records):
    """The records without their wall-clock fields (the only thing allowed to differ)."""
    drop = ("seconds", "wall", "time_s", "t_avg")
    return {m: [{k: v for k, v in r.items() if not any(d in k for d in drop)} for r in rs]
            for m, rs in records.items()}


def test_two_workers_and_dask_give_the_same_study(study, tmp_path):
    """Same input, same output with any executor: local workers 2 and a Dask cluster give
    the records and paired comparisons of the in-process run (issue 17 item 4)."""
    two = cs.clutter_shift(tmp_path / "w2", runs=3, seed=2, scenario=short(), resolution=40,
                           workers=2)
    assert _timeless(two.records) == _timeless(study.records)
    assert [c.to_dict() for c in two.paired] == [c.to_dict() for c in study.paired]
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        dk = cs.clutter_shift(tmp_path / "dask", runs=3, seed=2, scenario=short(),
                              resolution=40, executor="dask",
                              scheduler=cluster.scheduler_address)
    assert dk.computed == 12 and not dk.errors
    assert _timeless(dk.records) == _timeless(study.records)
    assert [c.to_dict() for c in dk.paired] == [c.to_dict() for c in study.paired]


def test_any_registered_estimator_joins_and_is_paired_with_gmm(tmp_path):
    from mhtrack.clutter.forgetting import ForgettingGMMClutter

    sc = preset("crossing", scans=6)
    assert isinstance(cs.make_estimator("fgmm", sc), ForgettingGMMClutter)
    with pytest.raises(ValueError, match="unknown method 'nope'"):
        cs.make_estimator("nope", sc)
    r = CliRunner().invoke(reproduce, ["clutter-shift", "--runs", "2", "--workers", "1",
                                       "--preset", "crossing", "--method", "gmm",
                                       "--method", "fgmm", "--out", str(tmp_path),
                                       "--no-progress"])
    assert r.exit_code == 0, r.output
    assert "fgmm vs gmm" in r.stdout
    res = json.loads((tmp_path / "results.json").read_text())
    assert res["params"]["scenario"] == "crossing"
    assert set(res["params"]["methods"]) == {"gmm", "fgmm"}
    bad = CliRunner().invoke(reproduce, ["clutter-shift", "--method", "nope",
                                         "--out", str(tmp_path / "x")])
    assert bad.exit_code == 2 and "nope" in bad.output
