"""``track`` and ``run`` end to end through the CLI."""

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
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
    # the file read back is what the library's tracker gives on the polar plots read with
    # the scenario's radars (fused: three sensors), column for column
    from mhtrack.build import default_config, make_tracker
    from mhtrack.experiments.pipeline import track
    from mhtrack.io import read_plots
    from mhtrack.scenario import load_scenario

    sc = load_scenario(tmp_path / "scenario.toml")
    plots = replace(read_plots(tmp_path / "plots.csv", sensors={s.id: s for s in sc.sensors}),
                    scan_times=(sc.scan_indices(), sc.scan_times()))
    assert plots.R is not None  # polar plots: each carries its own covariance
    want = track(make_tracker("mht-agmm", default_config(sc)), plots,
                 fusion="adaptive-kmeans").tracks
    got = read_tracks(tmp_path / "tracks.csv")
    assert len(got) == len(want) > 0
    for f in ("scan", "track_id", "plot", "tentative"):
        np.testing.assert_array_equal(getattr(got, f), getattr(want, f))
    for f in ("time", "x", "y", "vx", "vy"):
        np.testing.assert_allclose(getattr(got, f), getattr(want, f), rtol=1e-12)


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
    """Three radars: the default tracker (mht-agmm) and fusion (adaptive K-means) are what
    naming them explicitly gives, and fusing differs from tracking the raw plots."""
    runs = {}
    for name, extra in (("default", ()), ("explicit", ("--tracker", "mht-agmm", "--fusion",
                                                       "adaptive-kmeans")),
                        ("raw", ("--fusion", "none"))):
        code, _, stderr = invoke("run", "multiradar", "--seed", "1", "--birth",
                                      "modified-logic", *extra, "--json", "--no-progress",
                                      "--out", str(tmp_path / name))
        assert code == 0, stderr
        runs[name] = (tmp_path / name / "tracks.csv").read_bytes()
    assert runs["explicit"] == runs["default"]
    assert runs["raw"] != runs["default"]


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
    from mhtrack.build import MAX_TRACKER_PD, default_config
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


@pytest.fixture(scope="module")
def small_crossing(tmp_path_factory) -> Path:
    """Plots of 10 crossing scans, moved away from their scenario.toml (kept as s.toml)."""
    out = tmp_path_factory.mktemp("small")
    code, _, stderr = invoke("simulate", "crossing", "--seed", "1", "--scans", "10",
                             "--out", str(out / "sim"))
    assert code == 0, stderr
    (out / "p").mkdir()
    (out / "sim" / "plots.csv").rename(out / "p" / "plots.csv")
    (out / "sim" / "scenario.toml").rename(out / "s.toml")
    return out


def _edit_plots(src: Path, dst: Path, edit) -> Path:
    """Copy a plots CSV, applying ``edit(fields)`` to every data row's list of fields."""
    lines = src.read_text().splitlines()
    rows = [lines[0]] + [",".join(edit(line.split(","))) for line in lines[1:]]
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_text("\n".join(rows) + "\n")
    return dst


def test_track_refuses_a_huge_scan_gap_quickly(small_crossing, tmp_path):
    def shift(f):
        return [str(int(f[0]) + 10**9) if int(f[0]) > 5 else f[0], *f[1:]]

    bad = _edit_plots(small_crossing / "p" / "plots.csv", tmp_path / "plots.csv", shift)
    code, _, stderr = invoke("track", str(bad), "--out", str(tmp_path / "t.csv"),
                             "--no-progress")
    assert code != 0 and "Traceback" not in stderr
    assert f"{bad}, line " in stderr and "follows scan 5" in stderr and "1000000006" in stderr
    assert not (tmp_path / "t.csv").exists()


def test_track_rejects_plots_outside_or_off_the_scenario_scans(small_crossing, tmp_path):
    plots, scenario = small_crossing / "p" / "plots.csv", str(small_crossing / "s.toml")
    extra = tmp_path / "extra" / "plots.csv"
    extra.parent.mkdir()
    extra.write_text(plots.read_text() + "11,11,0,1,2,-1\n")
    code, _, stderr = invoke("track", str(extra), "--scenario", scenario,
                             "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code != 0 and "Traceback" not in stderr
    assert "column 'scan': scan 11 is not a scan of the scenario" in stderr
    assert "(scans 1 to 10); 1 row(s) are outside it" in stderr

    def slow(f):
        return [f[0], repr(float(f[1]) * 1.5), *f[2:]]

    off = _edit_plots(plots, tmp_path / "off" / "plots.csv", slow)
    code, _, stderr = invoke("track", str(off), "--scenario", scenario,
                             "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code != 0 and "Traceback" not in stderr
    assert f"{off}, line 2, column 'time': scan 1 has time 1.5 s, but the scenario" in stderr
    assert "gives 1.0 s" in stderr
    code, _, stderr = invoke("track", str(plots), "--scenario", scenario,
                             "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code == 0, stderr


def test_track_warns_about_polar_plots_without_scenario(tmp_path, caplog):
    code, _, stderr = invoke("simulate", "multiradar", "--seed", "2", "--scans", "3",
                             "--clutter-rate", "2", "--out", str(tmp_path / "sim"))
    assert code == 0, stderr
    (tmp_path / "p").mkdir()
    plots = (tmp_path / "sim" / "plots.csv").rename(tmp_path / "p" / "plots.csv")
    with caplog.at_level("WARNING", logger="mhtrack"):
        code, _, stderr = invoke("track", str(plots), "--out", str(tmp_path / "t.csv"),
                                 "--no-progress")
    assert code == 0, stderr
    assert "range/bearing columns (polar plots)" in caplog.text and "--scenario" in caplog.text


def test_track_area_ignores_and_reports_wild_plots(small_crossing, tmp_path, caplog):
    from mhtrack.io import read_plots
    from mhtrack.pipeline.options import survey_area
    from mhtrack.sources.memory import MemorySource

    def _plots_area(path, table):  # the area the pipeline takes from the plots' survey
        return survey_area(str(path), MemorySource(table).survey())

    plots = small_crossing / "p" / "plots.csv"
    rows = iter(range(10**6))

    def wild(f):
        return [*f[:3], "1e8", *f[4:]] if next(rows) == 7 else f

    bad = _edit_plots(plots, tmp_path / "plots.csv", wild)
    with caplog.at_level("WARNING", logger="mhtrack"):
        area = _plots_area(bad, read_plots(bad)).area
    assert "1 of " in caplog.text and "far outside" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING", logger="mhtrack"):
        assert _plots_area(plots, read_plots(plots)).area == pytest.approx(area, rel=0.05)
    assert "far outside" not in caplog.text
    assert area < 1e8
    with caplog.at_level("WARNING", logger="mhtrack"):
        code, _, stderr = invoke("track", str(bad), "--out", str(tmp_path / "t.csv"),
                                 "--no-progress")
    assert code == 0, stderr
    assert "far outside" in caplog.text


def test_run_on_rotating_radars_simulates_as_simulate_does(tmp_path):
    """``run`` on a rotating-radar preset follows ``simulate``'s attributes default: its
    plots file is ``simulate``'s, byte for byte (attributes on, or off with
    ``--no-attributes``)."""
    from mhtrack.io import read_plots
    from mhtrack.io.sensors import read_sensors

    for name, flag in (("on", ()), ("off", ("--no-attributes",))):
        d = tmp_path / name
        code, _, stderr = invoke("run", "radars-clutter", "--seed", "2", "--scans", "6",
                                 "--out", str(d / "run"), *flag)
        assert code == 0, stderr
        code, _, stderr = invoke("simulate", "radars-clutter", "--seed", "2", "--scans", "6",
                                 "--out", str(d / "sim"), *flag)
        assert code == 0, stderr
        assert (d / "run" / "plots.csv").read_bytes() == (d / "sim" / "plots.csv").read_bytes()
        plots = read_plots(d / "run" / "plots.csv", sensors=read_sensors(d / "sim" /
                                                                         "sensors.toml"))
        assert (plots.attrs is not None) == (name == "on")
