"""ASTERIX datagrams as a source: any iterable of datagrams (a socket reader, a capture
file's packets) decoded in memory, chunk by chunk, into frames (``docs/sources.md``).

Each datagram's data blocks are decoded by :class:`~mhtrack.io.asterix.decode.Decoder`
(a block equal to one of the last 4 096 received, however late, is dropped — redundant
LANs, :func:`~mhtrack.io.asterix.duplicates.stream_filter` —; CAT048 and CAT001 plots,
reports that are no plots left out; CAT034/CAT002 sweep marks and sites; other parts
counted and skipped, one warning line per kind at the end); times of day go on one
monotonic axis (:class:`~mhtrack.io.asterix.timeaxis.TimeAxis`, with the
datagrams' capture times where given); every :data:`CHUNK` plots are converted to the
local frame — ground range (:func:`~mhtrack.io.asterix.api.ground_ranges`) then
:func:`~mhtrack.io.timed_plots.polar_plots`, the conversion of ``mhtrack convert`` +
``read_timed_plots`` — and pushed through the re-order buffer and the framer
(:class:`~mhtrack.sources.timed.TimedStream`).

Radars: the sensors file's, else those whose site came in I034/120
(:func:`~mhtrack.io.asterix.sites.sensors_with_sites`); the plots of a radar with no
known site are skipped, and one warning line at the end lists those radars.

With ``sectors=True`` a radar's frames are also cut at its own sectors: each plot is in
the sector its radar's last CAT034/CAT002 north marker or sector crossing received
before it opened (arrival order: a radar sends a sector's message before the next
sector's plots), a frame holds one sector's plots (at most ``frame_s``: radars without
sector messages keep today's rule), the marks close it (:mod:`~mhtrack.sources.marks`).
Off by default: ``mhtrack export``'s recordings carry crossings every 45°: cutting there
changes their frames (and tracks) from those of their plots table.

A plot's file row is its 0-based number in decoding order (the row ``mhtrack convert``
gives it, skipped radars included). Frame lengths come from the sensors' periods
(``SensorSet``); a radar without one gets :data:`~mhtrack.frames.DEFAULT_FRAME_S`.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from typing import Any

import numpy as np

from mhtrack.frames import frame_lengths
from mhtrack.io.asterix.decode import MARKS, Decoder, plot_columns, sweep_periods
from mhtrack.io.asterix.duplicates import stream_filter
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.sites import sensors_with_sites, skipped_line
from mhtrack.io.asterix.timeaxis import TimeAxis
from mhtrack.io.plot_attributes import decoded_attributes
from mhtrack.io.reorder import DEFAULT_REORDER_WINDOW_S
from mhtrack.io.reorder import kept as kept_by_buffer
from mhtrack.models.radars import SensorSet
from mhtrack.records import Scan
from mhtrack.sources.base import CAUGHT_UP, IDLE, Source, SourceStats, Survey
from mhtrack.sources.gather import Gathered
from mhtrack.sources.marks import restored, row_place, template_of, with_marks
from mhtrack.sources.positions import local_positions
from mhtrack.sources.timed import TimedStream

#: Plots decoded before they are converted and pushed on (memory: a few hundred kB).
CHUNK = 1024
Datagram = bytes | tuple[bytes, float | None]


class DatagramSource(Source):
    """Frames from datagrams of ASTERIX data blocks: each ``bytes``, or ``(bytes,
    capture time)`` with the capture time in POSIX seconds (or ``None``). ``sensors``
    gives radars' sites, errors and (optionally) periods; a radar it lacks is taken from
    its CAT034 site (I034/120) or skipped (module docstring). Errors and warnings name
    ``name`` and the byte offset in the stream of datagrams (their payloads back to
    back)."""

    timed = True

    def __init__(self, datagrams: Iterable[Datagram], *, sensors: SensorSet | None = None,
                 name: str = "datagrams", reorder_window_s: float | None = None,
                 fast: bool = True, sectors: bool = False, chunk: int = CHUNK,
                 axis: TimeAxis | None = None, first_frame: int = 0, first_row: int = 0,
                 not_before: float | None = None,
                 pending: Mapping[str, Any] | None = None,
                 hold: Callable[[], bool] | None = None,
                 recent: str | None = None, keep_rows: int | None = None,
                 release: str = "time") -> None:
        super().__init__()
        if chunk < 1:
            raise ValueError(f"chunk must be >= 1 plot, got {chunk!r}")
        #: Plots converted and passed on together at most (a live feed also passes on
        #: what it has decoded whenever no datagram is waiting:
        #: :data:`~mhtrack.sources.base.CAUGHT_UP`; the results do not depend on it, the
        #: conversion is element-wise).
        self.chunk = int(chunk)
        self.name = name
        self.given = sensors
        self.sensors = sensors
        self.window_s = (DEFAULT_REORDER_WINDOW_S if reorder_window_s is None
                         else float(reorder_window_s))
        if not self.window_s >= 0:
            raise ValueError(f"reorder_window_s must be >= 0, got {reorder_window_s!r}")
        self.fast = fast
        self.sectors = sectors
        #: Where each pass's time axis starts (``day0, latest``: a resumed live run
        #: continues its checkpoint's axis) and the number of its first frame;
        #: :attr:`axis` is the running pass's axis.
        self.axis_start = (None, None) if axis is None else (axis.day0, axis.latest)
        self.axis = TimeAxis()
        self.axis.day0, self.axis.latest = self.axis_start
        self.first_frame, self.first_row = int(first_frame), int(first_row)
        #: Plots before this time are late drops (a resumed run: its checkpoint's time).
        self.not_before = not_before
        #: Plots held by an earlier stream (:meth:`pending`), taken back first (its count
        #: of sweep marks numbers the sectors on); ``hold()`` true at the end of the
        #: input: keep the plots held (:attr:`held`), not framed (a live run stopped).
        self.restore, self.hold = pending, hold
        #: The duplicate filter's blocks of an earlier run (``DuplicateFilter.recent``),
        #: remembered first: a copy received before the stop and again after is taken once.
        self.recent_start = recent
        #: Each radar's count of sweep marks so far (a plot's ``sector``); the columns of
        #: the last converted plots (or restored ones): a sweep mark's row has them
        self.marks, self._template = restored(pending, sectors)
        #: :meth:`file_rows` knows the last ``keep_rows`` plots only (``None``: all; a
        #: live stream without end keeps its memory flat).
        self.keep_rows = keep_rows
        #: When a closed frame goes out (:mod:`~mhtrack.sources.framer`: ``"time"``,
        #: the order of ``track``; ``"radar"``, as soon as its own plots are in).
        self.release = release
        self.held: dict[str, Any] | None = None
        #: Plots decoded so far: the next plot's decoding-order number (its ``file_row``).
        self.decoded = 0
        self.problems = Problems()
        self._input = datagrams
        self._stream: TimedStream | None = None
        self._decoder: Decoder | None = None
        self._seen: set[int] = set()  # radars whose site was settled (kept or skipped)
        self._skipped: dict[int, list[int]] = {}  # radar -> [plots, first byte]

    def _datagrams(self, problems: Problems, decoder: Decoder
                   ) -> Iterator[tuple[int, Any, float | None]]:
        """``(byte offset, payload, capture time)`` of each datagram (a file: by ``decoder``)."""
        offset = 0
        for d in self._input:
            if d is IDLE or d is CAUGHT_UP:
                yield offset, d, None
                continue
            payload, when = (d, None) if isinstance(d, bytes | bytearray | memoryview) else d
            yield offset, payload, when
            offset += len(payload)

    def _decoded(self, problems: Problems, sweeps: Gathered | None = None,
                 convert: bool = True, idle: bool = False
                 ) -> Iterator[dict[str, np.ndarray]]:
        """Chunks of decoded plots in decoding order: converted (columns ``time, sensor,
        x, y, R, file_row, offset``; radars without a site left out) or, with ``convert``
        false, as decoded (:data:`~mhtrack.io.asterix.decode.PLOT_COLUMNS` with the time
        on the axis, ``offset``); sweep marks (time on the axis) go to ``sweeps``; with
        ``idle``, :data:`~mhtrack.sources.base.IDLE` where the input had one (after the
        chunk decoded before it)."""
        self._decoder = decoder = Decoder(fast=self.fast,
                                          duplicates=stream_filter())
        if self.recent_start is not None:
            decoder.duplicates.restore(self.recent_start)  # type: ignore[union-attr]
        self.axis = axis = TimeAxis()
        axis.day0, axis.latest = self.axis_start
        self.decoded = 0
        rows: list[tuple[Any, ...]] = []
        times: list[float] = []
        at_rows: list[int] = []
        self.marks, self._template = restored(self.restore, self.sectors)
        sector = self.marks
        in_sector: list[int] = []
        marks: list[tuple[float, int, int, int, int]] = []  # (time, radar, sector, place, byte)
        closing = self.sectors and convert  # marks go on with the plots: they close frames
        n = 0
        for offset, payload, when in self._datagrams(problems, decoder):
            if payload is IDLE or payload is CAUGHT_UP:  # what is decoded, then IDLE
                if rows or marks:
                    yield self._chunk(rows, times, at_rows, n, convert, in_sector, marks)
                    n += len(rows)
                    rows, times, at_rows, in_sector, marks = [], [], [], [], []
                if idle and payload is IDLE:
                    yield IDLE  # type: ignore[misc]
                continue
            for at, what, found in decoder.blocks(payload, offset, problems, when):
                t = axis.times_list([r[0] for r in found], when)
                if what == MARKS:
                    if sweeps is not None:
                        sweeps.extend((ti, *r[1:]) for ti, r in zip(t, found, strict=True))
                    for ti, r in zip(t, found, strict=True):
                        sector[r[1]] = sector.get(r[1], 0) + 1
                        if closing:
                            marks.append((ti, r[1], sector[r[1]], len(rows), at))
                    continue
                rows.extend(found)
                self.decoded = n + len(rows)
                times.extend(t)
                at_rows.extend([at] * len(found))
                if self.sectors:
                    in_sector.extend(sector.get(r[1], 0) for r in found)
                if len(rows) >= self.chunk:
                    yield self._chunk(rows, times, at_rows, n, convert, in_sector, marks)
                    n += len(rows)
                    rows, times, at_rows, in_sector, marks = [], [], [], [], []
        if rows or marks:
            yield self._chunk(rows, times, at_rows, n, convert, in_sector, marks)

    def _chunk(self, rows: list[tuple[Any, ...]], times: list[float], at: list[int],
               n0: int, convert: bool, in_sector: list[int],
               marks: list[tuple[float, int, int, int, int]] | None = None
               ) -> dict[str, np.ndarray]:
        p = plot_columns(rows)  # ADS-B reports add lat, lon, sigma; I048/130 its columns
        p["time"] = np.array(times, float)
        p["offset"] = np.asarray(at, np.int64)
        p["file_row"] = np.arange(n0, n0 + len(rows), dtype=np.int64)
        if self.sectors:
            p["sector"] = np.asarray(in_sector, np.int64)
        out = self._convert(p) if rows and convert else None
        if not (convert and self.sectors):
            return out if convert else p  # type: ignore[return-value]
        if out is not None:
            out["mark"] = np.zeros(out["time"].size, bool)
            self._template = template_of(out) or self._template
        return with_marks(out, marks or [], n0, self._template)

    def _convert(self, p: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Plots of radars with a known site and ADS-B reports with an accuracy, in the
        local frame; the others counted."""
        sensor, offset = p["sensor"], p["offset"]
        adsb = np.isfinite(p["lat"]) if "lat" in p else np.zeros(sensor.size, bool)
        first = (float(p["lat"][adsb][0]), float(p["lon"][adsb][0])) if adsb.any() else None
        self._adopt(np.unique(sensor[~adsb]).tolist(), np.unique(sensor[adsb]).tolist(),
                    first)
        ids = [s.id for s in self.sensors.sensors if s.kind != "polar" or s.has_site] \
            if self.sensors is not None else []  # a radar without a site is skipped
        ok = np.isin(sensor, np.asarray(ids, np.int64))
        for sid in np.unique(sensor[~ok]).tolist():
            mine = sensor == sid
            got = self._skipped.setdefault(sid, [0, int(offset[mine][0])])
            got[0] += int(mine.sum())
        if adsb.any():
            assert self.sensors is not None
            fallback = {s.id: np.nan if s.sigma is None else s.sigma
                        for s in self.sensors.sensors}
            sigma = np.where(np.isfinite(p["sigma"]), p["sigma"], np.array(
                [fallback.get(int(s), np.nan) for s in sensor]))
            blind = adsb & ok & ~np.isfinite(sigma)
            if blind.any():
                self.problems.add("no_accuracy", int(offset[blind][0]), int(blind.sum()))
            ok &= ~blind
            p["sigma"] = sigma
        p = {k: v[ok] for k, v in p.items()}
        adsb, sensor = adsb[ok], p["sensor"]
        out = {k: p[k] for k in ("time", "sensor", "file_row", "offset", "sector") if k in p}
        if "mode_3a" in p:  # the plots' attributes (every batch has these columns)
            out.update(decoded_attributes(p))
        if not sensor.size:
            return {**out, "x": np.zeros(0), "y": np.zeros(0), "R": np.zeros((0, 2, 2))}
        assert self.sensors is not None
        x, y, R = local_positions(self.sensors, p, adsb, self.name)
        return {**out, "x": x, "y": y, "R": R}

    def _adopt(self, radars: Sequence[int], adsb: Sequence[int] = (),
               first: tuple[float, float] | None = None) -> None:
        """Settle the sensors not seen before: the sensors file's, else (radars) their
        CAT034 site received so far or skipped until a site comes, (ADS-B stations) a
        sensor of kind ``adsb`` (:func:`~mhtrack.io.asterix.sites.sensors_with_sites`)."""
        new = [r for r in radars if r not in self._seen]
        new_adsb = [r for r in adsb if r not in self._seen]
        if not new and not new_adsb:
            return
        sites = self._decoder.sites if self._decoder is not None else {}
        self.sensors, skipped = sensors_with_sites(self.sensors, sites, new, self.name,
                                                   adsb=new_adsb, first_position=first)
        self._seen.update(r for r in (*new, *new_adsb) if r not in skipped)

    def _frame_lengths(self) -> dict[int, float]:
        sensors = self.sensors.sensors if self.sensors is not None else ()
        return frame_lengths({s.id: s.period for s in sensors})

    def __iter__(self) -> Iterator[Scan]:
        self.stats = SourceStats()
        self.problems = problems = Problems()
        self._skipped = {}
        self._stream = stream = TimedStream(
            self.name, self.stats, self._frame_lengths(), self.window_s,
            row_place,
            first_frame=self.first_frame, first_row=self.first_row,
            not_before=self.not_before, keep_rows=self.keep_rows, release=self.release)
        if self.restore is not None:
            yield from stream.restore(self.restore)
        for cols in self._decoded(problems, idle=True):
            if cols is IDLE:  # a live feed went quiet: close what is held
                yield from stream.idle()
            else:
                yield from stream.push(cols)
        if self.hold is not None and self.hold():
            self.held = stream.pending()
        else:
            yield from stream.finish()
        self.stats.skipped = dict(problems.counts)
        problems.warn(self.name)
        self._warn_skipped()

    def pending(self) -> dict[str, Any] | None:
        """The plots not yet in a frame given out (:meth:`TimedStream.pending`; after a
        held end, those held) and ``marks``, each radar's count of sweep marks (the
        sector numbers of the plots that follow); ``None`` before reading."""
        held = self.held or (None if self._stream is None else self._stream.pending())
        return None if held is None else {**held, "marks": dict(self.marks)}

    def recent_blocks(self) -> str | None:
        """The duplicate filter's recent blocks now (``DuplicateFilter.recent``: what a
        checkpoint keeps; before reading, those given)."""
        f = None if self._decoder is None else self._decoder.duplicates
        return self.recent_start if f is None else f.recent()

    @property
    def idles(self) -> int:
        """Times the input went quiet and the held frames were closed (``TimedStream.idle``)."""
        return 0 if self._stream is None else self._stream.idles

    @property
    def next_frame(self) -> int:
        """The number the next frame will get."""
        return self.first_frame if self._stream is None else self._stream.framer.n_frames

    @property
    def next_row(self) -> int:
        """The running row number (``Scan.rows``) the next plot will get."""
        return self.first_row if self._stream is None else self._stream.next_row

    def _warn_skipped(self) -> None:
        """One warning line listing the radars skipped for want of a site."""
        if not self._skipped:
            return
        n = sum(c for c, _ in self._skipped.values())
        first = min(at for _, at in self._skipped.values())
        self.stats.skipped["no_site"] = n
        logging.getLogger("mhtrack").warning(
            "%s", skipped_line(self.name, sorted(self._skipped), n, first))

    def file_rows(self, rows: np.ndarray) -> np.ndarray:
        """Each plot's 0-based number in decoding order."""
        if self._stream is None:
            raise RuntimeError("file_rows before the source was read")
        return self._stream.file_rows(rows)

    def periods_and_survey(self) -> tuple[dict[int, float], Survey]:
        """One pass over the input: the radars (:meth:`_adopt`: the sensors file's, else
        their CAT034 sites), their periods from their CAT034 marks
        (:func:`~mhtrack.io.asterix.decode.sweep_periods`) and the :class:`Survey`
        (every kept plot's ``x, y``). The plots of radars the sensors file lists are
        converted as they come (40 octets a plot kept: ``x, y``, time, sensor, row, in
        :class:`~mhtrack.sources.gather.Gathered` buffers); the others wait, as decoded,
        for the sites of the whole input. Reads the datagrams: only for a replayable
        input."""
        sweeps = Gathered({"time": float, "sensor": np.int64, "kind": np.int64,
                           "azimuth": float, "period": float})
        self._seen, self.sensors = set(), self.given
        listed = np.asarray([s.id for s in self.given.sensors if s.kind == "polar" and
                             s.has_site] if self.given is not None else [], np.int64)
        self._seen.update(listed.tolist())
        got = Gathered({"x": float, "y": float, "time": float, "sensor": np.int64,
                        "file_row": np.int64})
        kept: set[int] = set()
        waiting = []
        for c in self._decoded(Problems(), sweeps, convert=False):
            now = np.isin(c["sensor"], listed)
            if "lat" in c:
                now &= ~np.isfinite(c["lat"])
            if now.any():
                done = self._convert({k: c[k][now] for k in (
                    "sensor", "slant_range", "bearing", "flight_level", "offset", "time",
                    "file_row")})
                got.add(done)
                kept.update(np.unique(done["sensor"]).tolist())
            if not now.all():
                waiting.append({k: v[~now] for k, v in c.items() if k in (
                    "sensor", "slant_range", "bearing", "flight_level", "offset", "lat",
                    "lon", "sigma", "time", "file_row")})
        sites = self._decoder.sites if self._decoder is not None else {}
        sensors_with_sites(self.given, sites, sorted(kept), self.name)  # warns if far
        radars: set[int] = set()
        for c in waiting:
            polar = ~np.isfinite(c["lat"]) if "lat" in c else np.ones(c["sensor"].size, bool)
            radars.update(np.unique(c["sensor"][polar]).tolist())
        self._adopt(sorted(radars))  # every site of the input is known now
        self._seen.update(radars)  # the radars left out stay out (one warning, later)
        for c in waiting:
            done = self._convert(c)
            got.add(done)
            kept.update(np.unique(done["sensor"]).tolist())
        marks = sweeps.columns()
        cols = got.columns()
        x, y, t, sensor = cols["x"], cols["y"], cols["time"], cols["sensor"]
        # the plots the re-order buffer will let through, replayed in decoding order
        order = np.argsort(cols["file_row"], kind="stable")
        on_time = np.zeros(x.size, bool)
        on_time[order] = kept_by_buffer(t[order], self.window_s)
        return sweep_periods(marks), Survey(int(x.size), tuple(sorted(kept)), x[on_time],
                                            y[on_time], sensor=sensor[on_time],
                                            time=t[on_time])

