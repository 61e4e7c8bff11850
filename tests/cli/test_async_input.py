"""``mhtrack track PLOTS --sensors FILE`` on timed plots: the wiring (sensor set to the
tracker, tracks with lat/lon and file rows) and bad input — one line naming file, line and
column, no traceback, each message checked verbatim."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow.csv as pacsv
import pytest
from click.testing import CliRunner
from site_sensors import sensors_toml

from mhtrack.cli.main import cli
from mhtrack.io import read_tracks
from mhtrack.io.sensors import read_sensors
from mhtrack.mht import StepStats
from mhtrack.pipeline import run as pipeline_run
from mhtrack.records import PlotTable, TrackTable
from mhtrack.sinks import FrameOutput

SENSORS = sensors_toml()
HEADER = "time,sensor,range,bearing,x,y,lat,lon\n"
GOOD = [
    "2024-05-01T12:00:03.250Z,1,150000,80.5,,,,",
    "2024-05-01T12:00:02.750Z,2,,,1000,2000,,",
    "2024-05-01T12:00:04.000Z,2,,,,,46.9,8.3",
    "2024-05-01T12:00:15.250Z,1,150200,80.6,,,,",
]


def invoke(*args: str) -> tuple[int, str, str]:
    r = CliRunner().invoke(cli, list(args))
    return r.exit_code, r.stdout, r.stderr


def files(tmp_path: Path, rows: list[str], header: str = HEADER) -> tuple[Path, Path]:
    plots, sensors = tmp_path / "plots.csv", tmp_path / "s.toml"
    plots.write_text(header + "\n".join(rows) + "\n")
    sensors.write_text(SENSORS)
    return plots, sensors


def edit(row: int, column: str, value: str) -> list[str]:
    """GOOD with one cell changed (row 0-based among the data rows)."""
    rows = [r.split(",") for r in GOOD]
    rows[row][HEADER.strip().split(",").index(column)] = value
    return [",".join(r) for r in rows]


BAD = [
    ("unknown-sensor", edit(2, "sensor", "7"),
     "line 4, column 'sensor': unknown sensor 7 (the sensors file lists 1, 2)"),
    ("polar-plot-of-sensor-without-site", [GOOD[0], "2024-05-01T12:00:03.500Z,2,500,10,,,,"],
     "line 3, column 'range': sensor 2 is a cartesian sensor without a site: a "
     "range/bearing plot needs a polar sensor with its site (lat/lon or position) in the "
     "sensors file"),
    ("missing-time", edit(1, "time", ""), "line 3, column 'time': value is missing"),
    ("unparseable-time", edit(0, "time", "noon"),
     "line 2, column 'time': value 'noon' is neither a number of seconds nor an ISO-8601 "
     "time of the form 2024-05-01T12:00:03.250Z (or with an offset such as +01:00)"),
    ("bad-iso-format", edit(2, "time", "2024-05-01T12:00:64Z"),
     "line 4, column 'time': value '2024-05-01T12:00:64Z' is neither a number of seconds "
     "nor an ISO-8601 time of the form 2024-05-01T12:00:03.250Z (or with an offset such "
     "as +01:00)"),
    ("iso-without-zone", edit(2, "time", "2024-05-01T12:00:04"),
     "line 4, column 'time': time '2024-05-01T12:00:04' has no time zone; end it with Z "
     "(UTC) or an offset such as +01:00"),
    ("number-after-number", [r.replace("2024-05-01T12:00:", "").replace("Z", "")
                             for r in GOOD[:2]] + ["4.0x,2,,,1,2,,"],
     "line 4, column 'time': value '4.0x' is not a number (the first row's time '03.250' "
     "is seconds, so every row's must be)"),
    ("range-negative", edit(3, "range", "-5"),
     "line 5, column 'range': range -5.0 m is negative"),
    ("range-absurd", edit(0, "range", "1.5e8"),
     "line 2, column 'range': range 150000000.0 m is beyond 20000 km, half-way round the "
     "Earth (a unit error?)"),
    ("bearing-outside", edit(0, "bearing", "361"),
     "line 2, column 'bearing': bearing 361.0 is outside [0, 360] degrees (clockwise from "
     "north)"),
    ("latitude-95", edit(2, "lat", "95"),
     "line 4, column 'lat': latitude 95.0 is outside [-90, 90] degrees"),
    ("polar-plot-missing-range", [GOOD[0].replace("150000,80.5", ","), *GOOD[1:]],
     "line 2, column 'range': value is missing (sensor 1 is a polar radar: its plots are "
     "range and bearing)"),
]


@pytest.mark.parametrize(("rows", "message"), [c[1:] for c in BAD], ids=[c[0] for c in BAD])
def test_bad_timed_plots_give_one_located_line(tmp_path, rows, message):
    plots, sensors = files(tmp_path, rows)
    code, _, stderr = invoke("track", str(plots), "--sensors", str(sensors),
                             "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code == 2
    assert stderr == f"Error: {plots}, {message}\n"
    assert not (tmp_path / "t.csv").exists()


def test_a_plot_beyond_the_reorder_window_is_dropped_with_one_line(tmp_path, caplog):
    """Line 6 (12:00:03) comes after line 5 (12:00:15.25) has released the plots up to
    12:00:04 to the tracker (window 2 s): it cannot be put in order, so the file is
    tracked without it and one warning line names the file, the lateness and the line."""
    late = "2024-05-01T12:00:03.000Z,2,,,1500,2500,,"
    plots, sensors = files(tmp_path, [*GOOD, late])
    with caplog.at_level("WARNING", logger="mhtrack"):
        code, _, stderr = invoke("track", str(plots), "--sensors", str(sensors),
                                 "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code == 0, stderr
    lines = [r.getMessage() for r in caplog.records if "dropped" in r.getMessage()]
    assert len(lines) == 1
    assert lines[0].startswith(f"{plots}: 1 plot dropped, late by 12.2 s"), lines[0]
    assert "line 6" in lines[0]
    # a row 3 s out of order that nothing released yet is re-ordered, not dropped
    caplog.clear()
    plots, sensors = files(tmp_path, edit(3, "time", "2024-05-01T12:00:01.000Z"))
    with caplog.at_level("WARNING", logger="mhtrack"):
        code, _, stderr = invoke("track", str(plots), "--sensors", str(sensors),
                                 "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code == 0, stderr
    assert not [r for r in caplog.records if "dropped" in r.getMessage()]


def test_range_without_bearing_column(tmp_path):
    plots, sensors = files(tmp_path, ["0.5,1,1000"], header="time,sensor,range\n")
    code, _, stderr = invoke("track", str(plots), "--sensors", str(sensors),
                             "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code == 2
    assert stderr == (f"Error: {plots}: column 'range' is present without column 'bearing'; "
                      "give both or neither\n")


def test_polar_plots_without_a_sensors_file(tmp_path):
    plots, _ = files(tmp_path, ["0.5,1,1000,10"], header="time,sensor,range,bearing\n")
    code, _, stderr = invoke("track", str(plots), "--out", str(tmp_path / "t.csv"),
                             "--no-progress")
    assert code == 2
    assert stderr == (f"Error: {plots}: range/bearing plots need the radar sites: read them "
                      "with a sensors file (mhtrack track --sensors FILE)\n")


def test_timed_plots_refuse_a_scenario(tmp_path):
    plots, sensors = files(tmp_path, GOOD)
    code, _, stderr = invoke("track", str(plots), "--scenario", str(sensors),
                             "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code == 2 and "holds timed plots (no scan column)" in stderr


def test_track_passes_the_sensor_set_and_writes_geodetic_tracks(tmp_path, monkeypatch):
    """The wiring: the tracker gets the converted timed table and the SensorSet; the tracks
    file names the plots' rows in the user's file and carries lat, lon."""
    plots, sensors = files(tmp_path, GOOD)
    seen: dict = {}

    def fake_steps(tracker, frames, **kw):  # the pipeline's stepping, replaced
        scans = list(frames)  # every frame read (the source maps rows after it is read)
        table = PlotTable.from_scans(scans)
        seen.update(kw, table=table, tracker=tracker, file_rows=frames.file_rows)
        k = int(np.flatnonzero(table.time == table.time.max())[0])  # the last polar plot
        tr = TrackTable(np.array([table.scan[k]]), np.array([table.time[k]]), np.array([1]),
                        table.x[k:k + 1], table.y[k:k + 1], np.array([100.0]),
                        np.array([0.0]), np.array([k]))
        yield FrameOutput(scans[0], tr, TrackTable.empty(), StepStats(0, 0, 0, 0, 0, 0, 1, 0.0))

    monkeypatch.setattr(pipeline_run, "step_frames", fake_steps)
    # the history as reported: the fake rows carry no covariance to smooth with
    code, stdout, stderr = invoke("track", str(plots), "--sensors", str(sensors),
                                  "--out", str(tmp_path / "t.csv"), "--no-progress",
                                  "--output", "history")
    assert code == 0, stderr
    from mhtrack.mht.coverage import RadarCoverage

    coverage = seen["tracker"].coverage  # the radars' coverage and clutter come from the file
    assert isinstance(coverage, RadarCoverage) and coverage.sensors == read_sensors(sensors)
    assert seen["fusion"] == "none"
    table = seen["table"]
    assert seen["file_rows"](np.arange(len(table))).tolist() == [1, 0, 2, 3]
    out = pacsv.read_csv(tmp_path / "t.csv").to_pydict()
    assert out["plot"] == [3]  # GOOD[3] is line 5 of the file: data row 3
    frame = read_sensors(sensors).frame()
    lat, lon = frame.to_geodetic(table.x[3], table.y[3])
    assert (out["lat"][0], out["lon"][0]) == (float(lat), float(lon))
    ve, vn = frame.velocity_to_geodetic(table.x[3], table.y[3], 100.0, 0.0)
    assert (out["vx"][0], out["vy"][0]) == (float(ve), float(vn))
    assert out["vx_grid"] == [100.0] and stdout.startswith("mht-agmm: 1 frames, 1 tracks")
    back = read_tracks(tmp_path / "t.csv")
    assert back.vx.tolist() == [100.0] and back.x[0] == table.x[3]


def test_track_runs_end_to_end_on_timed_plots(tmp_path):
    plots, sensors = files(tmp_path, GOOD)
    code, _, stderr = invoke("track", str(plots), "--sensors", str(sensors),
                             "--out", str(tmp_path / "t.csv"), "--no-progress")
    assert code == 0, stderr
    assert "lat" in (tmp_path / "t.csv").read_text().splitlines()[0].split(",")
