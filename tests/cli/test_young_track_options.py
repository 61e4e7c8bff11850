"""``--startup-density`` and ``--defer-tentative`` on ``track`` and ``run``: the CLI gives
the tracks the Python API gives with ``MHTConfig(startup_density=True,
defer_tentative=True)`` (and other tracks than without them, on a scene that starts busy:
40 targets present at the first scan among clutter); ``--startup-density`` with an
initiator birth is refused in one line."""

import dataclasses

import numpy as np
import pytest
from click.testing import CliRunner

from mhtrack.build import config_with, default_config, make_tracker, plots_area
from mhtrack.cli.main import cli
from mhtrack.experiments.pipeline import track
from mhtrack.io import read_plots, write_plots, write_tracks
from mhtrack.models.clutter import UniformClutter
from mhtrack.scenario import Target, preset, simulate

KAPPA = "5e-7"  # 32 uniform clutter plots a scan over crossing's 8 km square


@pytest.fixture(scope="module")
def plots_file(tmp_path_factory):
    """40 targets on a grid, all present at scan 1, 15 scans, in dense clutter."""
    rng = np.random.default_rng(5)
    sc = preset("crossing")
    g = np.linspace(-3000.0, 3000.0, 8)
    xy = [(x, y) for x in g for y in g[:5]]
    heading = rng.uniform(0, 2 * np.pi, len(xy))
    targets = tuple(Target(id=i + 1, state=(x, 150 * np.cos(h), y, 150 * np.sin(h)),
                           birth=1, death=15)
                    for i, ((x, y), h) in enumerate(zip(xy, heading, strict=True)))
    sc = dataclasses.replace(sc, scans=(1, 15), targets=targets,
                             clutter=UniformClutter(sc.region, float(KAPPA) * sc.region.area))
    path = tmp_path_factory.mktemp("young") / "plots.csv"
    write_plots(simulate(sc, seed=2).plots, path)
    return path


def _cli(plots_file, out, *args):
    r = CliRunner().invoke(cli, ["track", str(plots_file), "--out", str(out), "--tracker",
                                 "mht", "--clutter-density", KAPPA, "--no-progress", *args])
    assert r.exit_code == 0, r.output
    return out.read_bytes()


def _api(plots_file, out, **changes):
    table = read_plots(plots_file)
    cfg = config_with(default_config(area=plots_area(table.x, table.y).area), **changes)
    trk = make_tracker("mht", cfg, clutter_density=float(KAPPA))
    write_tracks(track(trk, table, name="mht", fusion="none").tracks, out, None, plots=table)
    return out.read_bytes()


def test_flags_set_the_configuration(plots_file, tmp_path):
    got = _cli(plots_file, tmp_path / "cli.csv", "--startup-density", "--defer-tentative")
    assert got == _api(plots_file, tmp_path / "api.csv", startup_density=True,
                       defer_tentative=True)
    assert _cli(plots_file, tmp_path / "plain.csv") == _api(plots_file, tmp_path / "p.csv")
    assert got != (tmp_path / "plain.csv").read_bytes()
    for flag, field in (("--startup-density", "startup_density"),
                        ("--defer-tentative", "defer_tentative")):
        one = _cli(plots_file, tmp_path / f"{field}.csv", flag)
        assert one == _api(plots_file, tmp_path / f"api-{field}.csv", **{field: True})
        assert one != (tmp_path / "plain.csv").read_bytes(), flag


def test_startup_density_needs_every_plot_births(plots_file, tmp_path):
    r = CliRunner().invoke(cli, ["track", str(plots_file), "--out", str(tmp_path / "t.csv"),
                                 "--birth", "logic", "--startup-density"])
    assert r.exit_code == 2
    assert "--startup-density goes with --birth every-plot (not logic)" in r.output
    r = CliRunner().invoke(cli, ["run", "crossing", "--scans", "3", "--birth", "hough",
                                 "--startup-density", "--out", str(tmp_path / "r")])
    assert r.exit_code == 2
    assert "--startup-density goes with --birth every-plot (not hough)" in r.output
