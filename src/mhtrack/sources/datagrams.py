"""ASTERIX datagrams as a source: any iterable of datagrams (a socket reader, a capture
file's packets) decoded in memory, chunk by chunk, into frames (``docs/sources.md``).

Each datagram's data blocks are decoded by :class:`~mhtrack.io.asterix.decode.Decoder`
(CAT048 plots, CAT034 sweep marks; other parts counted and skipped, one warning line per
kind at the end); times of day go on one monotonic axis
(:class:`~mhtrack.io.asterix.timeaxis.TimeAxis`, with the datagrams' capture times where
given); every :data:`CHUNK` plots are converted to the local frame — ground range
(:func:`~mhtrack.io.asterix.api.ground_ranges`) then
:func:`~mhtrack.io.timed_plots.polar_plots`, the conversion of ``mhtrack convert`` +
``read_timed_plots`` — and pushed through the re-order buffer and the framer
(:class:`~mhtrack.sources.timed.TimedStream`).

A plot's file row is its 0-based number in decoding order (the row ``mhtrack convert``
gives it). Frame lengths come from the sensors' periods (``SensorSet``); a radar without
one gets frames of :data:`~mhtrack.frames.DEFAULT_FRAME_S`.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import Any

import numpy as np

from mhtrack.errors import InputError
from mhtrack.frames import frame_lengths
from mhtrack.io.asterix.api import ground_ranges
from mhtrack.io.asterix.decode import Decoder, plot_columns, sweep_periods
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import TimeAxis
from mhtrack.io.timed_plots import DEFAULT_REORDER_WINDOW_S, polar_plots
from mhtrack.models.radars import SensorSet
from mhtrack.records import Scan
from mhtrack.sources.base import Source, SourceStats, Survey
from mhtrack.sources.reorder import kept
from mhtrack.sources.timed import TimedStream

#: Plots decoded before they are converted and pushed on (memory: a few hundred kB).
CHUNK = 1024
Datagram = bytes | tuple[bytes, float | None]


class DatagramSource(Source):
    """Frames from datagrams of ASTERIX data blocks: each ``bytes``, or ``(bytes,
    capture time)`` with the capture time in POSIX seconds (or ``None``). ``sensors``
    gives every radar's site, errors and (optionally) period; a radar missing from it is
    an error. Errors and warnings name ``name`` and the byte offset in the stream of
    datagrams (their payloads back to back)."""

    timed = True

    def __init__(self, datagrams: Iterable[Datagram], *, sensors: SensorSet,
                 name: str = "datagrams", reorder_window_s: float | None = None,
                 fast: bool = True) -> None:
        super().__init__()
        self.name = name
        self.sensors = sensors
        self.window_s = (DEFAULT_REORDER_WINDOW_S if reorder_window_s is None
                         else float(reorder_window_s))
        if not self.window_s >= 0:
            raise ValueError(f"reorder_window_s must be >= 0, got {reorder_window_s!r}")
        self.fast = fast
        self.problems = Problems()
        self._input = datagrams
        self._stream: TimedStream | None = None

    def _datagrams(self, problems: Problems) -> Iterator[tuple[int, Any, float | None]]:
        """``(byte offset, payload, capture time)`` of each datagram."""
        offset = 0
        for d in self._input:
            payload, when = (d, None) if isinstance(d, bytes | bytearray | memoryview) else d
            yield offset, payload, when
            offset += len(payload)

    def _decoded(self, problems: Problems, sweeps: list[tuple[Any, ...]] | None = None
                 ) -> Iterator[dict[str, np.ndarray]]:
        """Chunks of decoded, converted plots (columns ``time, sensor, x, y, R, file_row,
        offset``), in decoding order; sweep marks (time on the axis) go to ``sweeps``."""
        decoder, axis = Decoder(fast=self.fast), TimeAxis()
        rows: list[tuple[Any, ...]] = []
        times: list[float] = []
        at_rows: list[int] = []
        n = 0
        for offset, payload, when in self._datagrams(problems):
            for at, cat, found in decoder.blocks(payload, offset, problems):
                t = axis.times_list([r[0] for r in found], when)
                if cat == 34:
                    if sweeps is not None:
                        sweeps.extend((ti, *r[1:]) for ti, r in zip(t, found, strict=True))
                    continue
                rows.extend(found)
                times.extend(t)
                at_rows.extend([at] * len(found))
                if len(rows) >= CHUNK:
                    yield self._convert(rows, times, at_rows, n)
                    n += len(rows)
                    rows, times, at_rows = [], [], []
        if rows:
            yield self._convert(rows, times, at_rows, n)

    def _convert(self, rows: list[tuple[Any, ...]], times: list[float],
                 at: list[int], n0: int) -> dict[str, np.ndarray]:
        p = plot_columns(rows)
        sensor, offset = p["sensor"], np.asarray(at, np.int64)
        self._check_radars(sensor, offset)
        rng = ground_ranges(self.sensors, sensor, p["slant_range"], p["bearing"],
                            p["flight_level"])
        x, y, R = np.empty(sensor.size), np.empty(sensor.size), np.empty((sensor.size, 2, 2))
        for sid in np.unique(sensor).tolist():
            mine = sensor == sid
            x[mine], y[mine], R[mine] = polar_plots(self.sensors, sid, rng[mine],
                                                    p["bearing"][mine])
        return {"time": np.array(times, float), "sensor": sensor, "x": x, "y": y, "R": R,
                "file_row": np.arange(n0, n0 + sensor.size, dtype=np.int64),
                "offset": offset}

    def _check_radars(self, sensor: np.ndarray, offset: np.ndarray) -> None:
        """Every radar is a polar sensor of the sensors file with a lat/lon site."""
        ids = self.sensors.ids
        missing = ~np.isin(sensor, np.asarray(ids, np.int64))
        if missing.any():
            s = int(sensor[missing][0])
            raise InputError(
                f"{self.name}, byte {int(offset[missing][0])}: radar {s} (SAC {s >> 8}, "
                f"SIC {s & 0xFF}) is not in the sensors file (it lists "
                f"{', '.join(map(str, ids))}); add it, id = SAC·256 + SIC", file=self.name)
        for sid in np.unique(sensor).tolist():
            s = self.sensors.sensor(sid)
            if s.kind != "polar" or s.lat is None:
                at = int(offset[sensor == sid][0])
                raise InputError(f"{self.name}, byte {at}: sensor {sid} of the sensors file "
                                 "is not a polar radar with a lat/lon site (its ASTERIX "
                                 "plots are range and bearing)", file=self.name)

    def _frame_lengths(self) -> dict[int, float]:
        return frame_lengths({s.id: s.period for s in self.sensors.sensors})

    def __iter__(self) -> Iterator[Scan]:
        self.stats = SourceStats()
        self.problems = problems = Problems()
        self._stream = stream = TimedStream(
            self.name, self.stats, self._frame_lengths(), self.window_s,
            lambda first: f"byte {first['offset']} (plot {first['file_row']})")
        for cols in self._decoded(problems):
            yield from stream.push(cols)
        yield from stream.finish()
        self.stats.skipped = dict(problems.counts)
        problems.warn(self.name)

    def file_rows(self, rows: np.ndarray) -> np.ndarray:
        """Each plot's 0-based number in decoding order."""
        if self._stream is None:
            raise RuntimeError("file_rows before the source was read")
        return self._stream.file_rows(rows)

    def periods_and_survey(self) -> tuple[dict[int, float], Survey]:
        """One pass over the input: the radars' periods from their CAT034 marks
        (:func:`~mhtrack.io.asterix.decode.sweep_periods`) and the :class:`Survey`
        (every plot's ``x, y``). Reads the datagrams: only for a replayable input."""
        sweeps: list[tuple[Any, ...]] = []
        xs, ys, ts, sensors = [], [], [], set()
        for cols in self._decoded(Problems(), sweeps):
            xs.append(cols["x"])
            ys.append(cols["y"])
            ts.append(cols["time"])
            sensors.update(np.unique(cols["sensor"]).tolist())
        cols = list(zip(*sweeps, strict=True)) if sweeps else [()] * 5
        marks = {k: np.array(c, dtype=d) for k, c, d in zip(
            ("time", "sensor", "kind", "azimuth", "period"), cols,
            (float, np.int64, np.int64, float, float), strict=True)}
        x = np.concatenate(xs) if xs else np.zeros(0)
        y = np.concatenate(ys) if ys else np.zeros(0)
        on_time = kept(np.concatenate(ts) if ts else np.zeros(0), self.window_s)
        return sweep_periods(marks), Survey(int(x.size), tuple(sorted(sensors)),
                                            x[on_time], y[on_time])
