"""``reproduce p2``: P2's θ sweeps (Figs. 3–4), Figs. 2 and 12–15, Tables 1–2."""

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from mhtrack.build import make_initiator
from mhtrack.cli.reproduce_commands import reproduce
from mhtrack.experiments.initiation_runs import fused_scans, run_initiation
from mhtrack.experiments.jobs import run_seeds
from mhtrack.experiments.p2 import reproduce_p2
from mhtrack.experiments.p2.aggregate import aggregate
from mhtrack.experiments.p2.constants import FIGURES, MODIFIED_HOUGH_LABELS, THETAS_DEG
from mhtrack.experiments.p2.jobs import make_jobs, p2_scenario, run_job
from mhtrack.initiation import Window, sliding_windows
from mhtrack.initiation.logic import leg_angle, sweep_modified_logic
from mhtrack.metrics.initiation import initiable_targets, initiation_metrics, track_targets
from mhtrack.reports.p2 import write_p2_report
from mhtrack.scenario import simulate

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
THETAS = (10.0, 40.0)
SIGMAS = (20.0, 40.0)
RATES = (50.0, 100.0)


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("p2")
    repro = reproduce_p2(out, runs=2, seed=5, thetas=THETAS, sigmas=SIGMAS, rates=RATES,
                         workers=1)
    write_p2_report(repro)
    return out, repro


def again(out):
    repro = reproduce_p2(out, runs=2, seed=5, thetas=THETAS, sigmas=SIGMAS, rates=RATES,
                         workers=1)
    write_p2_report(repro)
    return repro


def test_files_exist_and_png(study):
    out, repro = study
    assert not repro.errors
    for name in (*FIGURES.values(), "tables.md", "report.md", "results.json"):
        assert (out / name).is_file(), name
    for name in FIGURES.values():
        assert (out / name).read_bytes()[:8] == PNG_MAGIC, name
    report = (out / "report.md").read_text()
    for name in FIGURES.values():
        assert f"]({name})" in report


def test_tables_show_the_measured_numbers(study):
    out, _ = study
    res = json.loads((out / "results.json").read_text())
    tables = (out / "tables.md").read_text()
    for m, label in (("modified-logic", "modified 3/4 logic"),
                     ("modified-hough", MODIFIED_HOUGH_LABELS["best"])):
        row = next(line for line in tables.splitlines() if line.startswith(f"| {label} |"))
        me = res["methods"][m]
        assert f"| {me['p_true']:.3f} | {me['p_false']:.3f} |" in row


def test_curves_are_the_ratios_of_their_counts(study):
    """p_true = found / initiable targets, p_false = false / (false + found) (P2's
    reading, duplicates once), p_false_tracks = false / tracks, per θ."""
    out, _ = study
    res = json.loads((out / "results.json").read_text())
    assert res["thetas_deg"] == list(THETAS)
    # 2 σr at λ = 50 and 2 λ at σr = 20, sharing (20, 50)
    points = {(c["sigma_range"], c["clutter_rate"]) for c in res["curves"]}
    assert points == {(20.0, 50.0), (40.0, 50.0), (20.0, 100.0)}
    for c in res["curves"]:
        assert c["runs"] == 2 and c["n_windows"] == 14  # 7 windows of 4 of 10 scans
        for i in range(len(THETAS)):
            assert c["p_true"][i] == c["found"][i] / c["n_targets"]
            assert c["p_false"][i] == c["false"][i] / (c["false"][i] + c["found"][i])
            assert c["p_false_tracks"][i] == c["false"][i] / c["tracks"][i]
            assert c["tracks_per_window"][i] == c["tracks"][i] / 14


def test_methods_agree_with_mhtrack_initiate(study):
    """The study's methods table equals what the ``initiate`` command's path
    (run_initiation + initiation_metrics) gives on the same seed, runs and settings."""
    out, _ = study
    res = json.loads((out / "results.json").read_text())
    sc = p2_scenario(20.0, 50.0)
    for m in ("modified-logic", "logic"):
        ini = make_initiator(m, theta_deg=20.0, gate_radius=300.0, v_min=50.0, v_max=400.0)
        run = run_initiation(sc, ini, runs=2, seed=5)
        got = initiation_metrics(
            [track_targets(w.track_origins, 3) for w in run.windows],
            [initiable_targets(w.target_ids, w.target_scans, 3) for w in run.windows],
            n_runs=2, window_seconds=[w.seconds for w in run.windows])
        assert res["methods"][m]["p_true"] == pytest.approx(got.p_true, rel=1e-12)
        assert res["methods"][m]["p_false"] == pytest.approx(got.p_false, rel=1e-12)


def test_hand_worked_aggregate():
    """Two grid chunks and one methods job with made-up counts, summed by hand."""
    jobs = [{"kind": "grid", "name": "g1", "sigma": 20.0, "rate": 50.0, "start": 0, "stop": 2},
            {"kind": "grid", "name": "g2", "sigma": 20.0, "rate": 50.0, "start": 2, "stop": 3},
            {"kind": "grid", "name": "lost", "sigma": 20.0, "rate": 50.0, "start": 3,
             "stop": 4}]
    res = {"g1": {"found": [3, 4], "false": [1, 2], "tracks": [4, 6], "n_targets": 5,
                  "n_windows": 2, "non_monotone_windows": 0},
           "g2": {"found": [1, 1], "false": [0, 2], "tracks": [1, 4], "n_targets": 3,
                  "n_windows": 1, "non_monotone_windows": 1}}
    a = aggregate(jobs, res, [10.0, 40.0])
    (c,) = a["curves"]
    assert (c["found"], c["false"], c["tracks"]) == ([4, 5], [1, 4], [5, 10])
    assert (c["n_targets"], c["n_windows"], c["runs"], c["non_monotone_windows"]) == (8, 3, 3, 1)
    assert c["p_true"] == [4 / 8, 5 / 8] and c["p_false"] == [1 / 5, 4 / 9]
    assert c["p_false_tracks"] == [1 / 5, 4 / 10]
    assert c["tracks_per_window"] == [5 / 3, 10 / 3]
    assert a["methods"]["runs"] == 0 and a["methods"]["logic"]["p_true"] is None


def _leg_angles(w, flat):
    """Leg angles (rad) of each track at its 3rd and later plots."""
    out = []
    for row in flat:
        z = w.z[row[row >= 0]]
        legs = np.diff(z, axis=0)
        out.append(leg_angle(legs[1:], legs[:-1]))
    return out


def test_angle_limit_filters(study):
    """The angle limit only admits legs with α ≤ θ: every track initiated at θ has all
    its leg angles ≤ θ, and θ = 180° is the plain 3/4 logic. The track *count* is not
    guaranteed monotone in θ (a miss branch exists only while the gate is empty; a new
    4-plot track removes its 3-plot sub-tracks): the study counts the windows where it
    decreases, checked here against the initiator run at each θ separately."""
    out, _ = study
    res = json.loads((out / "results.json").read_text())
    c = next(c for c in res["curves"] if (c["sigma_range"], c["clutter_rate"]) == (20, 50))
    n_tracks = np.zeros(len(THETAS), np.int64)
    non_monotone = 0
    for w in _windows(20.0, 50.0, seed=5, runs=2):
        counts = []
        for th in THETAS:
            flat = make_initiator("modified-logic", theta_deg=th).initiate(w).flat
            for a in _leg_angles(w, flat):
                assert np.all(a <= np.radians(th))
            counts.append(len(flat))
        n_tracks += counts
        non_monotone += int(np.any(np.diff(counts) < 0))
    assert n_tracks.tolist() == c["tracks"]
    assert non_monotone == c["non_monotone_windows"]


def _windows(sigma, rate, seed, runs):
    sc = p2_scenario(sigma, rate)
    for rs in run_seeds(seed, runs, "words"):
        fused, _ = fused_scans(list(simulate(sc, rs).plots.scans()), "adaptive-kmeans",
                               run_seed=rs)
        for win in sliding_windows(fused, 4):
            yield Window.from_scans(win)


@pytest.mark.parametrize(("sigma", "rate"), [(20.0, 50.0), (60.0, 150.0)])
def test_sweep_equals_initiator_at_every_theta(sigma, rate):
    """The one-pass sweep gives exactly the tracks of the modified-logic initiator."""
    thetas = THETAS_DEG
    for w in _windows(sigma, rate, seed=2, runs=1):
        swept = sweep_modified_logic(w, thetas)
        for th, flat in zip(thetas, swept, strict=True):
            ref = make_initiator("modified-logic", theta_deg=th).initiate(w).flat
            np.testing.assert_array_equal(flat, ref)
        # θ = 180°: the angle test never rejects — the plain 3/4 logic
        np.testing.assert_array_equal(swept[-1], make_initiator("logic").initiate(w).flat)


def test_job_hashes_of_an_old_study_are_unchanged():
    """Pinned hashes of jobs as the code before the job runner computed them: an old
    study directory resumes without recomputing anything."""
    jobs = make_jobs(2, 3, [10.0, 40.0], [20.0], [50.0], chunk=50)
    assert [(j.key, j.hash[:16]) for j in jobs] == [
        ("grid-s20-l50-r0-2", "32d8dbce20f5e23c"), ("clustering-s20-l0-r0-2", "a8f6a909857bda9f"),
        ("methods-s20-l50-r0-2", "15410c9625aa95b6")]


def test_resume_skips_finished_jobs(study):
    out, repro = study
    assert repro.computed == len(list((out / "jobs").glob("*.json")))
    before = json.loads((out / "results.json").read_text())
    second = again(out)
    assert second.computed == 0 and second.skipped == repro.computed
    after = json.loads((out / "results.json").read_text())
    assert after["curves"] == before["curves"]
    # a deleted job file and a corrupted one are recomputed, and only those
    victims = sorted((out / "jobs").glob("grid-*.json"))[:2]
    victims[0].unlink()
    victims[1].write_text(victims[1].read_text()[:40])
    third = again(out)
    assert third.computed == 2
    assert json.loads((out / "results.json").read_text())["curves"] == before["curves"]


def test_jobs_are_plain_and_chunked():
    jobs = make_jobs(120, 3, THETAS, SIGMAS, RATES, chunk=50)
    names = [j.key for j in jobs]
    assert len(names) == len(set(names))
    assert sum(j.params["kind"] == "grid" for j in jobs) == 3 * 3  # 3 grid points × 3 chunks
    assert {(j.params["start"], j.params["stop"]) for j in jobs} == {(0, 50), (50, 100),
                                                                     (100, 120)}
    for j in jobs:
        assert json.loads(json.dumps(j.as_dict())) == j.as_dict()
    small = run_job({**jobs[0].params, "start": 0, "stop": 1})
    assert set(small) >= {"found", "false", "tracks", "n_targets", "n_windows"}
    assert all(isinstance(v, int) for v in small["tracks"])
    assert math.isfinite(small["seconds"])


def test_cli_help():
    from mhtrack.cli.main import cli  # every command's options (-v, -q, --progress)

    r = CliRunner().invoke(cli, ["reproduce", "p2", "--help"])
    assert r.exit_code == 0, r.output
    for opt in ("--runs", "--out", "--seed", "--workers", "--dask-scheduler",
                "--progress", "--quiet"):
        assert opt in r.output
    r = CliRunner().invoke(reproduce, ["p2", "--out", "x", "--workers", "2",
                                       "--dask-scheduler", "tcp://h:1"])
    assert r.exit_code != 0 and "not both" in r.output
