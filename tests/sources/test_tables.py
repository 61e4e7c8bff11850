"""Plots tables as sources: the same frames as today's readers, bit for bit, and late rows
dropped with one warning instead of the whole file refused."""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import numpy as np
import pytest

from mhtrack.io.plots import read_plots
from mhtrack.io.sensors import read_sensors
from mhtrack.io.timed_plots import read_timed_plots
from mhtrack.sources import open_source
from mhtrack.sources.tables import TableSource

from .conftest import differences


def test_timed_table_gives_read_timed_plots_frames(opensky2: Path) -> None:
    sensors = read_sensors(opensky2 / "sensors.toml")
    table = read_timed_plots(opensky2 / "plots.csv", sensors)
    src = open_source(opensky2 / "plots.csv", sensors=sensors)
    assert isinstance(src, TableSource) and src.timed
    got = list(src)
    assert differences(list(table.scans()), got) == []
    rows = np.concatenate([s.rows for s in got])
    assert np.array_equal(src.file_rows(rows), table.file_row[rows])
    assert src.file_rows(np.array([-1, 0])).tolist() == [-1, int(table.file_row[0])]
    s = src.stats
    assert (s.plots_in, s.plots_out, s.frames, s.late_dropped) == (len(table), len(table),
                                                                   len(got), 0)
    survey = src.survey()
    assert survey.n_plots == len(table) and survey.sensors == (1, 2, 3)
    assert np.array_equal(np.sort(survey.x), np.sort(table.x))


def test_without_sensors_file(opensky2: Path, tmp_path: Path) -> None:
    sensors = read_sensors(opensky2 / "sensors.toml")
    xy = tmp_path / "xy.csv"
    t = read_timed_plots(opensky2 / "plots.csv", sensors)
    order = np.argsort(t.file_row)
    xy.write_text("time,sensor,x,y\n" + "".join(
        f"{t.time[i].item()!r},{t.sensor[i]},{t.x[i].item()!r},{t.y[i].item()!r}\n"
        for i in order))
    assert differences(list(read_timed_plots(xy).scans()), list(open_source(xy))) == []


def test_rows_out_of_order(opensky2: Path, tmp_path: Path,
                           caplog: pytest.LogCaptureFixture) -> None:
    """Row 100 moved 40 s later in the file: the source drops that row (one warning
    naming its line) and gives the frames of the file without it; read_timed_plots keeps
    and drops the same rows by the same rule (before: it refused the whole file, so that
    ``evaluate --plots`` refused a file ``track`` had taken); rows within the window are
    re-ordered."""
    sensors = read_sensors(opensky2 / "sensors.toml")
    lines = (opensky2 / "plots.csv").read_text().splitlines(keepends=True)
    t = [float(x.split(",")[0]) for x in lines[1:]]
    moved = 100
    to = next(i for i in range(len(t)) if t[i] > t[moved] + 40.0)
    late = lines[:moved + 1] + lines[moved + 2:to + 2] + [lines[moved + 1]] + lines[to + 2:]
    (tmp_path / "late.csv").write_text("".join(late))
    (tmp_path / "without.csv").write_text("".join(lines[:moved + 1] + lines[moved + 2:]))
    with caplog.at_level(logging.WARNING, logger="mhtrack"):
        read = read_timed_plots(tmp_path / "late.csv", sensors)
    read_warnings = [r.getMessage() for r in caplog.records]
    caplog.clear()
    src = open_source(tmp_path / "late.csv", sensors=sensors)
    with caplog.at_level(logging.WARNING, logger="mhtrack"):
        got = list(src)
    ref = list(read_timed_plots(tmp_path / "without.csv", sensors).scans())
    assert differences(ref, got) == []
    assert differences(list(read.scans()), got) == []
    assert to not in read.file_row.tolist() and read.file_row.size == len(t) - 1
    assert src.stats.late_dropped == 1
    lateness = t[to] - t[moved]  # the latest time before it arrived
    assert src.stats.max_late_s == pytest.approx(lateness) and 40.0 < lateness < 41.0
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert warnings == [f"{tmp_path / 'late.csv'}: 1 plot dropped, late by "
                        f"{lateness:.3g} s (after later plots had gone to the tracker, "
                        f"beyond the reorder window; first at line {to + 2})"]
    assert read_warnings == warnings  # one rule, one line
    # within the window: two neighbouring rows swapped come out sorted
    swap = lines[:1] + lines[1:50] + [lines[51], lines[50]] + lines[52:]
    (tmp_path / "swap.csv").write_text("".join(swap))
    src = open_source(tmp_path / "swap.csv", sensors=sensors)
    assert differences(list(read_timed_plots(tmp_path / "swap.csv", sensors).scans()),
                       list(src)) == []
    assert src.stats.reordered == 1 and src.stats.late_dropped == 0


def test_scan_table_with_and_without_scenario(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from mhtrack.cli.main import cli
    from mhtrack.scenario import load_scenario

    r = CliRunner().invoke(cli, ["simulate", "crossing", "--seed", "2", "--out",
                                 str(tmp_path)])
    assert r.exit_code == 0, r.output
    plots = tmp_path / "plots.csv"
    assert differences(list(read_plots(plots).scans()), list(open_source(plots))) == []
    sc = load_scenario(tmp_path / "scenario.toml")
    table = read_plots(plots, sensors={s.id: s for s in sc.sensors})
    table = dataclasses.replace(table, scan_times=(sc.scan_indices(), sc.scan_times()))
    src = open_source(plots, scenario=sc)
    got = list(src)
    assert differences(list(table.scans()), got) == []
    assert src.survey().n_frames == len(got) and src.scenario is sc
    assert src.file_rows(np.array([3, -1])).tolist() == [3, -1]


def test_evaluate_takes_the_plots_file_track_took(opensky2: Path, tmp_path: Path) -> None:
    """A timed plots file with one row 40 s late: ``track`` drops it with a warning, and
    ``evaluate --plots`` reads the same file by the same rule (before: it refused it)."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    lines = (opensky2 / "plots.csv").read_text().splitlines(keepends=True)
    t = [float(x.split(",")[0]) for x in lines[1:]]
    to = next(i for i in range(len(t)) if t[i] > t[100] + 40.0)
    (tmp_path / "late.csv").write_text("".join(lines[:101] + lines[102:to + 2] + [lines[101]]
                                               + lines[to + 2:]))
    sensors = str(opensky2 / "sensors.toml")
    r = CliRunner().invoke(cli, ["track", str(tmp_path / "late.csv"), "--sensors", sensors,
                                 "--out", str(tmp_path / "tracks.csv")])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, ["evaluate", str(tmp_path / "tracks.csv"),
                                 str(opensky2 / "truth.csv"), "--plots",
                                 str(tmp_path / "late.csv"), "--sensors", sensors, "--json"])
    assert r.exit_code == 0, r.output
    assert '"ospa' in r.output
