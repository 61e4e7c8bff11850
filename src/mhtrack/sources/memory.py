"""A source over a plots table already in memory: a simulation's plots, or a table read
whole from a file (:class:`MemorySource`)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.io.plots import plots_to_file_rows
from mhtrack.records import PlotTable, Scan
from mhtrack.sources.base import Source, Survey

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet
    from mhtrack.scenario import Scenario


class MemorySource(Source):
    """The scans (or frames) of a :class:`~mhtrack.records.PlotTable`, as
    :meth:`PlotTable.scans` yields them: the table is already in processing order, so
    nothing is re-ordered or dropped. ``Scan.rows`` are the table's rows; :meth:`file_rows`
    maps them to the rows of the file the table was read from
    (:func:`~mhtrack.io.plots.plots_to_file_rows`)."""

    def __init__(self, table: PlotTable, *, name: str = "<plots>",
                 sensors: SensorSet | None = None, scenario: Scenario | None = None) -> None:
        super().__init__()
        self.table = table
        self.name = name
        self.timed = bool(table.timed)
        self.iso_times = bool(table.iso_times)
        self.sensors = sensors
        self.scenario = scenario

    def __iter__(self) -> Iterator[Scan]:
        for scan in self.table.scans():
            self.stats.plots_in += len(scan)
            self.stats.plots_out += len(scan)
            self.stats.frames += 1
            yield scan

    def file_rows(self, rows: np.ndarray) -> np.ndarray:
        return plots_to_file_rows(rows, self.table)

    def survey(self) -> Survey:
        t = self.table
        return Survey(n_plots=len(t), sensors=tuple(np.unique(t.sensor).tolist()),
                      x=t.x, y=t.y, n_frames=t.n_scans, sensor=t.sensor, time=t.time)
