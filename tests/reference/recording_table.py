"""The former way a recording reached the tracker, kept as the tests' reference for the
streaming :class:`~mhtrack.sources.recording.AsterixSource`: decode the whole recording,
fill the radars' periods from CAT034, write the plots (with ground range) to a Parquet
file and read it back as a timed plots table."""

from __future__ import annotations

from pathlib import Path

from mhtrack.io.asterix import convert, read_recording, sensors_with_periods
from mhtrack.io.plots import read_plots
from mhtrack.models.radars import SensorSet
from mhtrack.records import PlotTable


def recording_table(rec: Path, sensors: SensorSet, tmp: Path) -> PlotTable:
    """The timed plots table of ``rec`` by the former decode → Parquet → read path."""
    decoded = read_recording(rec)
    sensors = sensors_with_periods(sensors, decoded)
    table_file = tmp / "plots.parquet"
    convert(rec, table_file, sensors, recording=decoded)
    return read_plots(table_file, sensors=sensors)
