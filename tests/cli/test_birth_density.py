"""--birth-density is λv per m² per scan, used as given: the CLI and the Python API give
the same tracks for the same number; left out, both take build.default_config's area
rule, and the CLI says which density it used."""

import json

import pytest
from click.testing import CliRunner

from mhtrack.build import config_with, default_config, make_tracker, plots_area
from mhtrack.cli.main import cli
from mhtrack.experiments.pipeline import run_scenario, track
from mhtrack.io import read_plots, write_tracks
from mhtrack.mht import MHTConfig
from mhtrack.scenario import preset


@pytest.fixture(scope="module")
def plots_file(tmp_path_factory):
    """crossing's plots in a folder of their own (no scenario.toml beside them)."""
    d = tmp_path_factory.mktemp("bd")
    r = CliRunner().invoke(cli, ["run", "crossing", "--seed", "1", "--scans", "25", "--out",
                                 str(d / "run"), "--json"])
    assert r.exit_code == 0, r.output
    (d / "alone").mkdir()
    path = d / "alone" / "plots.csv"
    path.write_bytes((d / "run" / "plots.csv").read_bytes())
    return path


def api_tracks(plots_file, config, out):
    table = read_plots(plots_file)
    result = track(make_tracker("mht-agmm", config), table, name="mht-agmm", fusion="none")
    write_tracks(result.tracks, out, None, plots=table)
    return out.read_bytes()


def cli_tracks(plots_file, out, *args):
    r = CliRunner().invoke(cli, ["track", str(plots_file), "--out", str(out), *args])
    assert r.exit_code == 0, r.output
    return out.read_bytes(), r.stdout


def test_a_given_density_is_used_as_is(plots_file, tmp_path):
    cli_bytes, stdout = cli_tracks(plots_file, tmp_path / "cli.csv", "--birth-density", "1e-7")
    api = api_tracks(plots_file, MHTConfig(new_target_density=1e-7), tmp_path / "api.csv")
    assert cli_bytes == api
    assert "new-target density" not in stdout


def test_the_default_is_the_area_rule_of_default_config_and_is_said(plots_file, tmp_path):
    table = read_plots(plots_file)
    box = plots_area(table.x, table.y)
    cfg = default_config(area=box.area)
    assert cfg.new_target_density == pytest.approx(6.4 / box.area)
    cli_bytes, stdout = cli_tracks(plots_file, tmp_path / "cli.csv")
    assert cli_bytes == api_tracks(plots_file, cfg, tmp_path / "api.csv")
    assert f"λv = {cfg.new_target_density:.4g} per m² per scan" in stdout
    assert "bounding box" in stdout
    # the box of these plots is smaller than P1's region: the rule is not P1's 1e-7 …
    assert cfg.new_target_density > 2e-7
    # … and the tracks differ from those of 1e-7, which is why the CLI says what it used
    assert cli_bytes != api_tracks(plots_file, MHTConfig(new_target_density=1e-7),
                                   tmp_path / "p1.csv")


def test_run_and_run_scenario_agree_for_the_same_number(tmp_path):
    r = CliRunner().invoke(cli, ["run", "crossing", "--seed", "2", "--scans", "20",
                                 "--birth-density", "3e-7", "--out", str(tmp_path / "r"),
                                 "--json"])
    assert r.exit_code == 0, r.output
    cli_summary = json.loads(r.stdout)
    sc = preset("crossing", scans=20)
    api = run_scenario(sc, 2, "mht-agmm", config_with(default_config(sc),
                                                      new_target_density=3e-7)).summary()
    for k in ("ospa_mean", "mota", "n_track_ids", "n_matches"):
        assert cli_summary[k] == api[k], k
