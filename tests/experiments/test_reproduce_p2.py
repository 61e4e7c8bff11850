"""``reproduce p2``: P2's θ sweeps (Figs. 3–4), Figs. 2 and 12–15, Tables 1–2."""

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from mhtrack.cli.reproduce_commands import reproduce
from mhtrack.experiments import reproduce_p2 as rp
from mhtrack.initiation import Window, make_initiator, sliding_windows
from mhtrack.initiation.logic import leg_angle
from mhtrack.initiation.runs import fused_scans, run_seeds
from mhtrack.scenario import simulate

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
THETAS = (10.0, 40.0)
SIGMAS = (20.0, 40.0)
RATES = (50.0, 100.0)


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("p2")
    repro = rp.reproduce_p2(out, runs=2, seed=5, thetas=THETAS, sigmas=SIGMAS, rates=RATES,
                            workers=1)
    return out, repro


def test_files_exist_and_png(study):
    out, repro = study
    assert not repro.errors
    for name in (*rp.FIGURES.values(), "tables.md", "report.md", "results.json"):
        assert (out / name).is_file(), name
    for name in rp.FIGURES.values():
        assert (out / name).read_bytes()[:8] == PNG_MAGIC, name
    report = (out / "report.md").read_text()
    for name in rp.FIGURES.values():
        assert f"]({name})" in report
    tables = (out / "tables.md").read_text()
    assert "114.5" in tables and "0.034" in tables


def test_curves_are_probabilities(study):
    out, _ = study
    res = json.loads((out / "results.json").read_text())
    assert res["thetas_deg"] == list(THETAS)
    # 2 σr at λ = 50 and 2 λ at σr = 20, sharing (20, 50)
    points = {(c["sigma_range"], c["clutter_rate"]) for c in res["curves"]}
    assert points == {(20.0, 50.0), (40.0, 50.0), (20.0, 100.0)}
    for c in res["curves"]:
        assert c["runs"] == 2 and c["n_windows"] == 14
        for key in ("p_true", "p_false"):
            assert len(c[key]) == len(THETAS)
            for v in c[key]:
                assert v is not None and 0.0 <= v <= 1.0, (key, v)
        # the same simulated windows for every θ: one set of initiable targets
        assert c["n_targets"] > 0
    for m in ("adaptive", "random"):
        assert 0.0 <= res["clustering"][m]["k_correct_rate"] <= 1.0
    for m in ("logic", "modified-logic", "hough", "modified-hough"):
        assert 0.0 <= res["methods"][m]["p_true"] <= 1.0
        assert 0.0 <= res["methods"][m]["p_false"] <= 1.0
        assert res["methods"][m]["t_window"] > 0


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
    sc = rp.p2_scenario(sigma, rate)
    for rs in run_seeds(seed, runs):
        fused, _ = fused_scans(list(simulate(sc, rs).plots.scans()), "adaptive-kmeans",
                               run_seed=rs)
        for win in sliding_windows(fused, 4):
            yield Window.from_scans(win)


@pytest.mark.parametrize(("sigma", "rate"), [(20.0, 50.0), (60.0, 150.0)])
def test_sweep_equals_initiator_at_every_theta(sigma, rate):
    """The one-pass sweep gives exactly the tracks of the modified-logic initiator."""
    thetas = rp.THETAS_DEG
    for w in _windows(sigma, rate, seed=2, runs=1):
        swept = rp.sweep_modified_logic(w, thetas)
        for th, flat in zip(thetas, swept, strict=True):
            ref = make_initiator("modified-logic", theta_deg=th).initiate(w).flat
            np.testing.assert_array_equal(flat, ref)
        # θ = 180°: the angle test never rejects — the plain 3/4 logic
        np.testing.assert_array_equal(swept[-1], make_initiator("logic").initiate(w).flat)


def test_seeds_depend_on_run_only():
    assert rp._seed_of(7, 3) == run_seeds(7, 10)[3] == run_seeds(7, 4)[3]


def test_resume_skips_finished_jobs(study):
    out, repro = study
    assert repro.computed == len(list((out / "jobs").glob("*.json")))
    before = json.loads((out / "results.json").read_text())
    again = rp.reproduce_p2(out, runs=2, seed=5, thetas=THETAS, sigmas=SIGMAS, rates=RATES,
                            workers=1)
    assert again.computed == 0 and again.skipped == repro.computed
    after = json.loads((out / "results.json").read_text())
    assert after["curves"] == before["curves"]
    # a deleted job file is recomputed, and only that one
    victim = next((out / "jobs").glob("grid-*.json"))
    victim.unlink()
    third = rp.reproduce_p2(out, runs=2, seed=5, thetas=THETAS, sigmas=SIGMAS, rates=RATES,
                            workers=1)
    assert third.computed == 1
    assert json.loads((out / "results.json").read_text())["curves"] == before["curves"]


def test_jobs_are_plain_and_seeded():
    jobs = rp.make_jobs(120, 3, THETAS, SIGMAS, RATES, chunk=50)
    names = [j["name"] for j in jobs]
    assert len(names) == len(set(names))
    assert sum(j["kind"] == "grid" for j in jobs) == 3 * 3  # 3 grid points × 3 chunks
    assert {(j["start"], j["stop"]) for j in jobs} == {(0, 50), (50, 100), (100, 120)}
    for j in jobs:
        json.dumps(j)
    small = rp.run_job({**jobs[0], "start": 0, "stop": 1})
    assert set(small) >= {"found", "false", "tracks", "n_targets", "n_windows"}
    assert all(isinstance(v, int) for v in small["tracks"])
    assert math.isfinite(small["seconds"])


def test_cli_help():
    r = CliRunner().invoke(reproduce, ["p2", "--help"])
    assert r.exit_code == 0, r.output
    for opt in ("--runs", "--out", "--seed", "--workers", "--dask-scheduler",
                "--no-progress"):
        assert opt in r.output
    r = CliRunner().invoke(reproduce, ["p2", "--out", "x", "--workers", "2",
                                       "--dask-scheduler", "tcp://h:1"])
    assert r.exit_code != 0 and "not both" in r.output
