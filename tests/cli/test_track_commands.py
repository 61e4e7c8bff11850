"""``track`` and ``run`` end to end through the CLI."""

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli
from mhtrack.io import read_tracks


def invoke(*args: str) -> tuple[int, str, str]:
    r = CliRunner().invoke(cli, list(args))
    return r.exit_code, r.stdout, r.stderr


RUN = ["run", "crossing", "--seed", "3", "--clutter", "uniform", "--clutter-rate", "10",
       "--tracker", "mht", "--clutter-density", "1.5625e-7", "--scans", "40",
       "--no-progress"]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("run")
    code, stdout, stderr = invoke(*RUN, "--out", str(out), "--json")
    assert code == 0, stderr
    return out, json.loads(stdout)


def test_run_writes_everything(run_dir):
    out, summary = run_dir
    for name in ("plots.csv", "truth.csv", "tracks.csv", "scenario.toml", "metrics.json",
                 "scene.png", "metrics.png"):
        assert (out / name).is_file(), name
    assert summary["tracker"] == "mht"
    assert 0 < summary["t_avg"] < 1.0
    assert len(summary["ospa"]) == 40
    assert json.loads((out / "metrics.json").read_text())["ospa_mean"] == summary["ospa_mean"]


def test_run_finds_the_targets(run_dir):
    _, s = run_dir
    # 40 scans: targets 1 and 4 live all along, target 3 from scan 30; with 10 uniform
    # clutter plots per scan and the true density, the MHT should follow them.
    assert s["ospa_mean"] < 200
    assert s["n_tracks"] >= 3


def test_run_is_deterministic(run_dir, tmp_path):
    out, _ = run_dir
    code, _, stderr = invoke(*RUN, "--out", str(tmp_path), "--json")
    assert code == 0, stderr
    assert (tmp_path / "tracks.csv").read_bytes() == (out / "tracks.csv").read_bytes()


def test_track_on_plots_file_matches_run(run_dir, tmp_path):
    out, _ = run_dir
    dst = tmp_path / "tracks.csv"
    code, stdout, stderr = invoke("track", str(out / "plots.csv"), "--out", str(dst),
                                  "--tracker", "mht", "--clutter-density", "1.5625e-7",
                                  "--no-progress")
    assert code == 0, stderr
    assert "tracks" in stdout
    assert dst.read_bytes() == (out / "tracks.csv").read_bytes()
    t = read_tracks(dst)
    assert len(t) > 0 and (t.plot >= -1).all()


def test_output_modes(run_dir, tmp_path):
    """The default history output holds the online output plus each track's tentative
    rows; the confirmation delay is the same in both, the association rate is higher."""
    out, hist = run_dir
    code, stdout, stderr = invoke(*RUN, "--out", str(tmp_path), "--json", "--output", "online")
    assert code == 0, stderr
    online = json.loads(stdout)
    assert hist["output"] == "history" and online["output"] == "online"
    h, o = read_tracks(out / "tracks.csv"), read_tracks(tmp_path / "tracks.csv")
    assert h.tentative.sum() > 0 and o.tentative.sum() == 0
    ho = h.online()
    for f in ("scan", "track_id", "plot"):
        assert (getattr(ho, f) == getattr(o, f)).all()
    assert len(h) > len(o)
    assert hist["delay"] == online["delay"] and hist["delay_max"] >= 1
    assert hist["rcc"] > online["rcc"]


def test_track_polar_plots_uses_scenario_sensors(tmp_path):
    code, _, stderr = invoke("simulate", "multiradar", "--seed", "2", "--scans", "6",
                             "--clutter-rate", "5", "--out", str(tmp_path))
    assert code == 0, stderr
    code, _stdout, stderr = invoke("track", str(tmp_path / "plots.csv"), "--out",
                                  str(tmp_path / "tracks.csv"), "--no-progress")
    assert code == 0, stderr
    assert read_tracks(tmp_path / "tracks.csv") is not None


def test_unknown_tracker_is_a_usage_error():
    code, _, stderr = invoke("run", "crossing", "--tracker", "nope")
    assert code == 2 and "nope" in stderr


def test_run_multiradar_with_modified_logic_birth(tmp_path):
    code, stdout, stderr = invoke("run", "multiradar", "--seed", "1", "--tracker", "mht-agmm",
                                  "--birth", "modified-logic", "--json", "--no-progress",
                                  "--out", str(tmp_path))
    assert code == 0, stderr
    s = json.loads(stdout)
    assert len(s["ospa"]) == 10 and s["ospa"][-1] < 100  # fused plots (default, 3 radars)
    t = read_tracks(tmp_path / "tracks.csv")
    assert len(t) > 0 and (t.plot >= -1).all()


def test_run_multiradar_default_tracker_with_birth_and_explicit_fusion(tmp_path):
    code, stdout, stderr = invoke("run", "multiradar", "--seed", "1", "--birth",
                                  "modified-logic", "--fusion", "adaptive-kmeans", "--json",
                                  "--no-progress", "--out", str(tmp_path))
    assert code == 0, stderr
    assert 0 < json.loads(stdout)["ospa_mean"] <= 500


def test_run_crossing_agmm_with_logic_birth(tmp_path):
    code, stdout, stderr = invoke("run", "crossing", "--tracker", "mht-agmm", "--birth",
                                  "logic", "--scans", "12", "--seed", "1", "--json",
                                  "--no-progress", "--out", str(tmp_path))
    assert code == 0, stderr
    s = json.loads(stdout)
    assert len(s["ospa"]) == 12 and s["tracker"] == "mht-agmm"


def test_track_with_birth_and_fusion_options(run_dir, tmp_path):
    out, _ = run_dir
    dst = tmp_path / "tracks.csv"
    code, _, stderr = invoke("track", str(out / "plots.csv"), "--out", str(dst),
                             "--tracker", "mht", "--clutter-density", "1.5625e-7",
                             "--birth", "logic",
                             "--fusion", "none", "--no-progress")
    assert code == 0, stderr
    t = read_tracks(dst)
    assert len(t) > 0 and len(set(t.track_id.tolist())) >= 2
    # the default (every-plot, one sensor: no fusion) still matches run's tracks
    dst2 = tmp_path / "default.csv"
    code, _, stderr = invoke("track", str(out / "plots.csv"), "--out", str(dst2),
                             "--tracker", "mht", "--clutter-density", "1.5625e-7",
                             "--birth", "every-plot",
                             "--no-progress")
    assert code == 0, stderr
    assert dst2.read_bytes() == (out / "tracks.csv").read_bytes()


def test_unknown_birth_or_fusion_is_a_usage_error():
    code, _, stderr = invoke("run", "crossing", "--birth", "nope")
    assert code == 2 and "nope" in stderr
    code, _, stderr = invoke("run", "crossing", "--fusion", "kmeans")
    assert code == 2 and "kmeans" in stderr


def test_clutter_density_needs_the_known_clutter_tracker():
    code, _, stderr = invoke("run", "crossing", "--clutter-density", "1e-7", "--scans", "3")
    assert code == 2
    assert "--clutter-density" in stderr and "mht-agmm" in stderr


def test_run_warns_when_mht_keeps_p1_kappa_on_denser_clutter(tmp_path, caplog):
    # 10 uniform clutter plots per scan over 6.4e7 m²: 1.5625e-7 per m², 156× P1's κ
    args = ("run", "crossing", "--clutter", "uniform", "--clutter-rate", "10", "--scans", "5",
            "--seed", "1", "--tracker", "mht", "--no-progress")
    with caplog.at_level("WARNING", logger="mhtrack"):
        code, _, stderr = invoke(*args, "--out", str(tmp_path / "a"))
    assert code == 0, stderr
    assert "--clutter-density 1.56e-07" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING", logger="mhtrack"):
        code, _, stderr = invoke(*args, "--out", str(tmp_path / "b"),
                                 "--clutter-density", "1.5625e-7")
    assert code == 0, stderr
    assert "clutter density" not in caplog.text


def test_run_takes_pd_and_sigma_of_a_single_cartesian_sensor():
    from mhtrack.experiments.pipeline import MAX_TRACKER_PD, default_config
    from mhtrack.scenario import preset
    from mhtrack.scenario.spec import from_dict

    d = preset("crossing").to_dict()
    d["sensors"][0].update(pd=0.7, sigma=20.0)
    cfg = default_config(from_dict(d))
    assert (cfg.p_detection, cfg.sigma_w) == (0.7, 20.0)
    d["sensors"][0]["pd"] = 1.0
    assert default_config(from_dict(d)).p_detection == MAX_TRACKER_PD
    # several (polar) sensors: fused scans, P1's 0.9 kept
    assert default_config(preset("multiradar")).p_detection == 0.9
