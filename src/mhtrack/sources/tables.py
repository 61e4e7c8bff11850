"""Plots tables (CSV or Parquet) as sources (``docs/sources.md``).

* **Timed plots** (no ``scan`` column): read, checked and converted to the local frame as
  :func:`mhtrack.io.timed_plots.read_timed_plots` does (the same code,
  :func:`~mhtrack.io.timed_plots.read_timed_columns`), then, in file order, through the
  re-order buffer and the framer (:class:`~mhtrack.sources.timed.TimedStream`): rows out
  of order within the window are re-ordered, later ones dropped and counted — where
  ``read_timed_plots`` refuses the file.
* **Scans** (a ``scan`` column): :func:`mhtrack.io.plots.read_plots`, with a scenario's
  sensors and scan times when one is given, yielded by :meth:`PlotTable.scans`.

The file is read whole (a table's columns are read by pyarrow at once); frames are cut
as they are yielded.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.frames import DEFAULT_FRAME_S, frame_lengths
from mhtrack.io._source import PathArg
from mhtrack.io._times import is_iso
from mhtrack.io.plots import check_scan_times, is_timed, read_plots
from mhtrack.io.reorder import DEFAULT_REORDER_WINDOW_S, kept
from mhtrack.io.timed_plots import read_timed_columns
from mhtrack.records import PlotTable, Scan
from mhtrack.sources.base import Source, SourceStats, Survey
from mhtrack.sources.timed import TimedStream

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet
    from mhtrack.scenario import Scenario


class TableSource(Source):
    """A plots table: timed plots (with an optional sensors file) or scans (with an
    optional scenario); which one by the file's columns (:func:`~mhtrack.io.plots.is_timed`).
    The file is read and checked on construction (located errors name it)."""

    def __init__(self, path: PathArg, *, sensors: SensorSet | None = None,
                 scenario: Scenario | None = None,
                 reorder_window_s: float | None = None) -> None:
        super().__init__()
        self.name = str(path)
        self.path = path
        self.timed = is_timed(path)
        self.window_s = (DEFAULT_REORDER_WINDOW_S if reorder_window_s is None
                         else float(reorder_window_s))
        if not self.window_s >= 0:
            raise ValueError(f"reorder_window_s must be >= 0, got {reorder_window_s!r}")
        self._stream: TimedStream | None = None
        if self.timed:
            if scenario is not None:
                raise ValueError(f"{path} holds timed plots (no scan column): their "
                                 "sensors come from a sensors file, not a scenario")
            self.sensors = sensors
            self._frame, self._cols = read_timed_columns(path, sensors)
            self.iso_times = is_iso(self._frame)
            if sensors is None and self._frame.has("range"):
                _warn_polar(path, timed=True)
            self._table: PlotTable | None = None
        else:
            if sensors is not None:
                raise ValueError(f"{path} holds scans (a scan column): their sensors come "
                                 "from a scenario, not a sensors file")
            self.scenario = scenario
            self._table = _read_scans(path, scenario)
            self.iso_times = self._table.iso_times

    def __iter__(self) -> Iterator[Scan]:
        self.stats = SourceStats()
        if self._table is not None:
            for scan in self._table.scans():
                self.stats.plots_in += len(scan)
                self.stats.plots_out += len(scan)
                self.stats.frames += 1
                yield scan
            return
        c, f = self._cols, self._frame
        self._stream = stream = TimedStream(
            self.name, self.stats, self._frame_lengths(), self.window_s,
            lambda first: f.src.where(int(first["file_row"])))  # type: ignore[call-overload]
        cols = {"time": c.time, "sensor": c.sensor, "x": c.x, "y": c.y,
                "file_row": np.arange(c.time.size, dtype=np.int64)}
        if c.R is not None:
            cols["R"] = c.R
        if c.origin is not None:
            cols["origin"] = c.origin
        if c.attrs is not None:
            cols.update(c.attrs.columns(polar=True))
        for a in range(0, c.time.size, CHUNK):
            yield from stream.push({k: v[a:a + CHUNK] for k, v in cols.items()})
        yield from stream.finish()

    def _frame_lengths(self) -> dict[int, float]:
        ids = np.unique(self._cols.sensor).tolist()
        if self.sensors is None:
            return dict.fromkeys(ids, DEFAULT_FRAME_S)
        return frame_lengths({s: self.sensors.sensor(s).period for s in ids})

    def file_rows(self, rows: np.ndarray) -> np.ndarray:
        """0-based data rows of the file (timed: through the re-ordering)."""
        rows = np.asarray(rows, np.int64)
        if self._table is not None:
            fr = self._table.file_row
            if fr is None:
                return rows.copy()
            return np.where(rows >= 0, fr[np.maximum(rows, 0)], -1)
        if self._stream is None:
            raise RuntimeError("file_rows before the source was read")
        return self._stream.file_rows(rows)

    def survey(self) -> Survey:
        """Every plot's ``x, y`` and the sensors; the number of scans of a scan table."""
        if self._table is not None:
            t = self._table
            return Survey(len(t), tuple(np.unique(t.sensor).tolist()), t.x, t.y, t.n_scans,
                          t.sensor, t.time)
        c = self._cols
        on_time = kept(c.time, self.window_s)  # the plots the re-order buffer lets through
        return Survey(int(c.time.size), tuple(np.unique(c.sensor).tolist()), c.x[on_time],
                      c.y[on_time], sensor=c.sensor[on_time], time=c.time[on_time])


#: Rows pushed through the re-order buffer at a time.
CHUNK = 4096


def _read_scans(path: PathArg, scenario: Scenario | None) -> PlotTable:
    """A scan table, with the scenario's sensors and every scan time when given; without
    a scenario, range/bearing columns are only carried along (:func:`_warn_polar`)."""
    if scenario is None:
        table = read_plots(path)
        if table.range is not None:
            _warn_polar(path, timed=False)
        return table
    table = read_plots(path, sensors={s.id: s for s in scenario.sensors})
    idx, times = scenario.scan_indices(), scenario.scan_times()
    check_scan_times(path, table, idx, times, "the scenario")
    return dataclasses.replace(table, scan_times=(idx, times))


def _warn_polar(path: PathArg, *, timed: bool) -> None:
    """Range/bearing columns without the sensors that place them: x, y are tracked."""
    option = "--sensors with the radars" if timed else "--scenario with the radar(s)"
    logging.getLogger("mhtrack").warning(
        "%s has range/bearing columns (polar plots), but no %s gives its sensors: they are "
        "ignored and x, y tracked as Cartesian plots with the tracker's σw; pass %s to use "
        "the polar measurement model", path, "sensors file" if timed else "scenario", option)
