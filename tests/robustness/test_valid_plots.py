"""Every plot the docs call valid is tracked (issue 33): a polar plot at range 0 (the
docs allow range ≥ 0) or 1e-300 made the tracker refuse the scan ("plot row 3 has an
invalid covariance"), because its converted covariance was singular. Read from a timed
plots file with a sensors file and tracked, through the library and the command."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from site_sensors import sensors_toml

from mhtrack import build
from mhtrack.cli.main import cli
from mhtrack.io import read_plots
from mhtrack.io.sensors import read_sensors
from mhtrack.models.linalg2 import det2

SENSORS = sensors_toml(4.0, cartesian=False)


def _files(tmp_path: Path, near: list[float]) -> tuple[Path, Path]:
    """A target flying away from the site at 100 m/s, one plot per rotation, and the
    ``near`` ranges (0, 1e-300, …) as extra plots of the first rotations."""
    rows = ["time,sensor,range,bearing"]
    for k in range(12):
        rows.append(f"{4.0 * k},1,{20e3 + 400.0 * k},{45.0}")
        if k < len(near):
            rows.append(f"{4.0 * k + 1.0},1,{near[k]!r},{90.0 * k}")
    plots = tmp_path / "plots.csv"
    plots.write_text("\n".join(rows) + "\n")
    sensors = tmp_path / "sensors.toml"
    sensors.write_text(SENSORS)
    return plots, sensors


NEAR = [0.0, 1e-300, 5e-324, 1.0, 0.0]


def test_plots_at_range_zero_are_read_with_positive_definite_covariances(
        tmp_path: Path) -> None:
    plots, sensors = _files(tmp_path, NEAR)
    table = read_plots(plots, sensors=read_sensors(sensors))
    assert table.R is not None
    assert (table.R[:, 0, 0] > 0).all() and (det2(table.R) > 0).all()
    np.linalg.cholesky(table.R)


def test_plots_at_range_zero_are_tracked(tmp_path: Path) -> None:
    plots, sensors = _files(tmp_path, NEAR)
    radars = read_sensors(sensors)
    table = read_plots(plots, sensors=radars)
    tracks = build.make_tracker("mht", sensors=radars, clutter_density=1e-9).run(table)
    assert len(tracks) > 0  # the target is tracked; before: ValueError at the first frame


@pytest.mark.parametrize("near", [[0.0], [1e-300]])
def test_track_command_takes_a_plot_at_range_zero(tmp_path: Path, near: list[float]) -> None:
    plots, sensors = _files(tmp_path, near)
    res = CliRunner().invoke(cli, ["track", str(plots), "--sensors", str(sensors), "--out",
                                   str(tmp_path / "tracks.csv")])
    assert res.exit_code == 0, res.output
    lines = (tmp_path / "tracks.csv").read_text().splitlines()
    assert lines[0].startswith("frame,time,track_id") and len(lines) > 1


def test_scan_plots_at_range_zero_are_tracked_and_a_singular_one_is_named(
        tmp_path: Path) -> None:
    """A scan file with a (simulated-style) polar radar: range 0 converts to a positive
    definite R (unbiased converted measurement, ``det = σr⁴(1 − λ'²)/4``) and is tracked;
    errors so small that ``R`` is singular in float64 (σθ = 1e-300°) are refused where
    the file is known — file, line and column — not by the tracker without a file."""
    from mhtrack.clutter.known import KnownClutter
    from mhtrack.errors import InputError
    from mhtrack.mht import MHTConfig, MHTTracker
    from mhtrack.models.sensors import PolarRadar

    rows = ["scan,time,sensor,x,y,range,bearing"]
    for k in range(6):
        rows.append(f"{k},{float(k)},0,0,0,{2000.0 + 100 * k},45.0")
        rows.append(f"{k},{float(k)},0,0,0,0.0,{30.0 * k}")
    path = tmp_path / "plots.csv"
    path.write_text("\n".join(rows) + "\n")
    table = read_plots(path, {0: PolarRadar(0, sigma_range=20.0, sigma_bearing_deg=0.3)})
    assert table.R is not None and (det2(table.R) > 0).all()
    MHTTracker(MHTConfig(), KnownClutter(1e-9)).run(table)
    with pytest.raises(InputError) as e:
        read_plots(path, {0: PolarRadar(0, sigma_range=20.0, sigma_bearing_deg=1e-300)})
    assert str(e.value).startswith(f"{path}, line 2, column 'range': range 2000")
    assert "not positive definite" in str(e.value)
