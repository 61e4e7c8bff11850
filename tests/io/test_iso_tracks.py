"""Tracks from plots with ISO-8601 times keep ISO-8601 times (issue 31,
docs/file-formats.md "Times"); tracks from numeric times stay numbers, byte for byte."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli
from mhtrack.io import read_tracks, write_tracks
from mhtrack.io.timed_plots import read_timed_plots
from mhtrack.records import TrackTable

T0 = dt.datetime(2024, 5, 1, 12, 0, 0, tzinfo=dt.UTC)


def _plots(path, iso):
    """Two crossing-free targets seen by one Cartesian sensor, 30 scans of 2 s."""
    lines = ["time,sensor,x,y"]
    for k in range(30):
        for j, (x0, vy) in enumerate(((0.0, 100.0), (5000.0, -80.0))):
            t = 2.0 * k + 0.01 * j + 0.123456
            stamp = (T0 + dt.timedelta(seconds=t)).isoformat().replace("+00:00", "Z")
            when = stamp if iso else repr(t)
            lines.append(f"{when},1,{x0 + 3.0 * k},{1000.0 + vy * t}")
    path.write_text("\n".join(lines) + "\n")
    return path


def _tracks(n=3):
    t = T0.timestamp() + np.array([0.110379, 1.305752, 2.5])
    return TrackTable(scan=np.arange(n), time=t, track_id=np.zeros(n, np.int64),
                      x=np.ones(n), y=np.ones(n), vx=np.ones(n), vy=np.ones(n),
                      plot=np.arange(n))


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_iso_plots_give_iso_tracks_that_read_back_bit_for_bit(tmp_path, suffix):
    plots = read_timed_plots(_plots(tmp_path / "plots.csv", iso=True))
    assert plots.iso_times
    tracks = _tracks()
    out = tmp_path / f"tracks{suffix}"
    write_tracks(tracks, out, plots=plots)
    if suffix == ".csv":
        first = out.read_text().splitlines()[1].split(",")[1]
        assert first == "2024-05-01T12:00:00.110378981Z"  # the float's own nanoseconds
        # independent: Python's datetime of the same POSIX seconds, to the microsecond
        got = dt.datetime.fromisoformat(first[:26] + "+00:00")
        assert got == dt.datetime.fromtimestamp(tracks.time[0], dt.UTC).replace(
            microsecond=got.microsecond) and abs(got.timestamp() - tracks.time[0]) < 1e-6
    else:
        assert str(pq.read_schema(out).field("time").type) == "timestamp[ns, tz=UTC]"
    assert read_tracks(out).time.tobytes() == tracks.time.tobytes()


def test_numeric_plots_give_numeric_tracks(tmp_path):
    plots = read_timed_plots(_plots(tmp_path / "plots.csv", iso=False))
    assert not plots.iso_times
    out = tmp_path / "tracks.csv"
    write_tracks(_tracks(), out, plots=plots)
    assert out.read_text().splitlines()[1].split(",")[1] == repr(float(_tracks().time[0]))


def test_track_command_keeps_iso_times(tmp_path):
    _plots(tmp_path / "plots.csv", iso=True)
    r = CliRunner().invoke(cli, ["track", str(tmp_path / "plots.csv"), "--out",
                                 str(tmp_path / "tracks.csv"), "--quiet"])
    assert r.exit_code == 0, r.output
    rows = (tmp_path / "tracks.csv").read_text().splitlines()[1:]
    assert rows and all(r.split(",")[1].startswith("2024-05-01T12:") and
                        r.split(",")[1].endswith("Z") for r in rows)
