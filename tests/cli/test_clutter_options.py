"""``--clutter-forgetting``, ``--birth-scaling``, ``--map-range-cell``, ``--map-sectors``
reach the tracker's ``clutter_params``; out of range or with a tracker whose estimator does
not take them they are usage errors naming the option."""

from __future__ import annotations

import click
import pytest
from click.testing import CliRunner

from mhtrack.cli.clutter_options import clutter_params
from mhtrack.cli.track_commands import run


def test_params_of_the_options():
    assert clutter_params("mht-map", 0.8, 1.0, 2000.0, 16) == {
        "forgetting": 0.8, "birth_scaling": 1.0, "range_cell": 2000.0, "n_azimuth": 16}
    assert clutter_params("mht-fgmm", 0.5, None, None, None) == {"forgetting": 0.5}
    assert clutter_params("mht-gmm", None, None, None, None) is None
    assert clutter_params("mht-mapgmm", None, 1.0, None, 16, clutter_half_life=30.0) == {
        "birth_scaling": 1.0, "n_azimuth": 16, "half_life": 30.0}
    with pytest.raises(click.UsageError, match="--clutter-half-life"):
        clutter_params("mht-gmm", None, None, None, None, clutter_half_life=30.0)
    with pytest.raises(click.UsageError,
                       match="--birth-scaling goes with --tracker mht-map or mht-mapgmm"):
        clutter_params("mht-fgmm", None, 1.0, None, None)
    with pytest.raises(click.UsageError, match="--clutter-forgetting"):
        clutter_params("mht-agmm", 0.9, None, None, None)


def test_run_passes_them_to_the_tracker(tmp_path, monkeypatch):
    import mhtrack.pipeline.options as po

    seen = {}
    real = po.make_tracker

    def spy(name, *a, **k):
        seen[name] = k.get("clutter_params")
        return real(name, *a, **k)

    monkeypatch.setattr(po, "make_tracker", spy)
    res = CliRunner().invoke(run, ["crossing", "--scans", "3", "--tracker", "mht-map",
                                   "--birth-scaling", "0.5", "--map-sectors", "8",
                                   "--out", str(tmp_path / "r")])
    assert res.exit_code == 0, res.output
    assert seen["mht-map"] == {"birth_scaling": 0.5, "n_azimuth": 8}


@pytest.mark.parametrize("args, where", [
    (["--tracker", "mht-map", "--clutter-forgetting", "0"], "--clutter-forgetting"),
    (["--tracker", "mht-map", "--clutter-forgetting", "1.5"], "--clutter-forgetting"),
    (["--tracker", "mht-map", "--birth-scaling", "nan"], "--birth-scaling"),
    (["--tracker", "mht-map", "--map-sectors", "0"], "--map-sectors"),
    (["--tracker", "mht-map", "--map-range-cell", "0.5"], "--map-range-cell"),
    (["--tracker", "mht-gmm", "--birth-scaling", "1"], "--birth-scaling"),
])
def test_bad_values_are_usage_errors(tmp_path, args, where):
    res = CliRunner().invoke(run, ["crossing", "--scans", "3", *args,
                                   "--out", str(tmp_path / "r")])
    assert res.exit_code == 2 and where in res.output, res.output


def test_forgetting_and_half_life_not_both(tmp_path):
    with pytest.raises(click.UsageError, match="not both"):
        clutter_params("mht-map", 0.8, None, None, None, clutter_half_life=30.0)
    res = CliRunner().invoke(run, ["crossing", "--scans", "3", "--tracker", "mht-fgmm",
                                   "--clutter-forgetting", "0.9", "--clutter-half-life", "20",
                                   "--out", str(tmp_path / "r")])
    assert res.exit_code == 2 and "not both" in res.output, res.output


def test_help_gives_the_estimators_defaults():
    """The defaults the help states are the estimators' own (clutter.radar_map.HALF_LIFE
    for map and mapgmm, clutter.forgetting.FORGETTING for fgmm)."""
    import inspect

    from mhtrack.clutter.forgetting import FORGETTING, ForgettingGMMClutter
    from mhtrack.clutter.radar_map import HALF_LIFE

    assert inspect.signature(ForgettingGMMClutter).parameters["half_life"].default is None
    text = " ".join(CliRunner().invoke(run, ["--help"], terminal_width=200).output.split())
    assert f"[map, mapgmm: {HALF_LIFE:g} s; fgmm: none, γ = {FORGETTING:g} per scan]" in text
    assert f"fgmm: {FORGETTING:g}]" in text
