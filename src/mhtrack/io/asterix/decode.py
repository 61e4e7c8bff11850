"""Target reports and service messages of a recording, decoded by libasterix into columns
(docs/file-formats.md, "ASTERIX recordings").

One plot per CAT048 record with I048/040 (measured position), I048/010 (data source) and
I048/140 (time of day), and per CAT001 plot record (its truncated time of day restored,
:mod:`~mhtrack.io.asterix.cat001`); the others are counted and skipped. Reports that are
no plot of a real target (no detection, test target, field monitor, simulated:
:mod:`~mhtrack.io.asterix.notplots`) are counted and left out; the plot type is kept
(``plot_type``). CAT034 (CAT002) north markers (I034/000 = 1) and sector crossings (= 2)
become the radars' sweep marks, and I034/120 the radars' sites. CAT021 ADS-B reports are
decoded by :mod:`~mhtrack.io.asterix.cat021`. A data block received twice (redundant LANs)
is kept once (:mod:`~mhtrack.io.asterix.duplicates`). Blocks of other categories (CAT062
system tracks among them: not plots), and blocks whose records do not decode to exactly
their length, are counted and skipped (libasterix's strict parsing).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix._lib import quantity
from mhtrack.io.asterix.cat001 import TimeRestorer, block001, block002, record001, record002
from mhtrack.io.asterix.cat021 import block021, record021
from mhtrack.io.asterix.characteristics import CHARACTERISTICS, characteristics
from mhtrack.io.asterix.columns import columns
from mhtrack.io.asterix.container import blocks
from mhtrack.io.asterix.duplicates import DuplicateFilter
from mhtrack.io.asterix.fast import reader034, reader048
from mhtrack.io.asterix.fill import fills_any_edition, whole_records
from mhtrack.io.asterix.framings import Unit, recognise, units
from mhtrack.io.asterix.notplots import flags048, plot_type048_of, reason
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import TimeAxis
from mhtrack.progress import Count

#: One nautical mile (m), the unit of I048/040 RHO.
NM_M = 1852.0
#: One flight level (m): 100 ft of 0.3048 m.
FL_M = 30.48

#: The plot columns, in output order (docs/file-formats.md).
PLOT_COLUMNS = ("time", "sensor", "sac", "sic", "slant_range", "bearing", "flight_level",
                "mode_3a", "address", "callsign", "track_number", "typ", "plot_type",
                "mode_3a_vg", "flight_level_vg")
#: The validity bits of I048/070 and /090 in the ``*_vg`` columns: ``2·V + G`` (V "not
#: validated", G "garbled"; 0 when the item is absent).
VG = "2·V + G"
#: The columns an ADS-B report (CAT021) adds to :data:`PLOT_COLUMNS`: WGS-84 position
#: (deg) and its σ per axis (m, from NACp/NUCp, :mod:`~mhtrack.io.asterix.cat021`).
ADSB_EXTRA = ("lat", "lon", "sigma")
#: Kinds of rows :meth:`Decoder.blocks` yields.
PLOTS, MARKS, ADSB = "plots", "marks", "adsb"


@dataclass
class Recording:
    """A decoded recording: ``plots`` (name -> array, :data:`PLOT_COLUMNS`, then
    :data:`ADSB_EXTRA` when it holds ADS-B reports; missing values NaN for floats, ``-1``
    for ints, ``""`` for text), ``sweeps`` (``time, sensor, kind``
    1 north marker / 2 sector crossing, ``azimuth`` deg, NaN for north markers;
    ``period`` s from I034/041, NaN when absent), ``sites`` (each radar's I034/120:
    :attr:`Decoder.sites`), the framing and the skipped parts."""

    name: str
    container: str
    plots: dict[str, np.ndarray]
    sweeps: dict[str, np.ndarray]
    problems: Problems = field(default_factory=Problems)
    sites: dict[int, tuple[float, float, float, int]] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.plots["time"].size)

    def periods(self) -> dict[int, float]:
        """Each radar's rotation period (s) from its CAT034 messages
        (:func:`sweep_periods`)."""
        return sweep_periods(self.sweeps)


def read_recording(path: str | Path, *, fast: bool = True, progress: bool = False
                   ) -> Recording:
    """Decode the plots (CAT048, CAT001), ADS-B reports (CAT021: rows of ``plots`` in file
    order, with ``lat, lon, sigma`` columns, NaN on the radars' rows, present only when
    the recording has any), sweep marks (CAT034, CAT002) and sites (I034/120) of a
    recording in any framing :func:`~mhtrack.io.asterix.framings.recognise` knows.
    Malformed parts, duplicates and reports that are no plots are counted in ``problems``
    (the caller warns); a file that is no recording raises
    :class:`~mhtrack.errors.InputError`. ``fast=False`` decodes every record with
    libasterix alone (the reference path of :mod:`~mhtrack.io.asterix.fast`). Times are
    on one monotonic axis (:mod:`~mhtrack.io.asterix.timeaxis`, capture times where the
    framing has them). ``progress``: a bar of the bytes decoded
    (:class:`~mhtrack.progress.Count`)."""
    name = str(path)
    data = Path(path).read_bytes()
    decoder = Decoder(fast=fast)
    kind = recognise(data, name, decoder.categories)
    problems = Problems()
    rows: list[tuple[Any, ...]] = []
    marks: list[tuple[Any, ...]] = []
    is_plot: list[bool] = []
    times: list[float] = []
    axis = TimeAxis()
    bar = Count(len(data), "decode", "B", progress, scale=True)
    for offset, when, payload in decoder.units(data, kind, name, problems):
        bar.to(offset)
        for _, what, found in decoder.blocks(payload, offset, problems, when):
            into = marks if what == MARKS else rows  # ADS-B reports beside the plots
            into.extend(found)
            is_plot.extend([what != MARKS] * len(found))
            times.extend(axis.times_list([r[0] for r in found], when))
    bar.to(len(data))
    bar.close()
    plots, sweeps = _columns(rows, marks, np.array(is_plot, bool),
                             np.array(times, float))
    return Recording(name, kind, plots, sweeps, problems, dict(decoder.sites))


#: The record reader of each category decoded by libasterix record by record (the
#: edition and UAP choice the decoding uses): a block judged by it is not parsed again.
OWN_RECORDS = {1: record001, 2: record002, 21: record021}
#: Blocks judged and not yet decoded whose records are kept (the walk over a raw stream
#: judges a few blocks ahead of the one decoded).
JUDGED_KEPT = 16


class Decoder:
    """Decodes data blocks, block by block, into plot rows (:data:`PLOT_COLUMNS`: CAT048
    through :mod:`~mhtrack.io.asterix.fast` unless ``fast=False``, CAT001), sweep marks
    (CAT034, CAT002) and ADS-B rows (CAT021, :data:`~mhtrack.io.asterix.cat021.COLUMNS`
    less the flags). A block already received within the duplicate window
    (``duplicates``; ``None``: none dropped) is counted (``duplicate``) and skipped;
    reports that are no plots are counted (``not_plot``) and left out. :attr:`sites`
    gathers each radar's I034/120: ``sensor -> (lat, lon, height m, byte offset)``, the
    first one sent."""

    def __init__(self, *, fast: bool = True,
                 duplicates: DuplicateFilter | bool | None = True) -> None:
        base, gen = _lib.modules()
        self.bits = base.Bits.from_bytes
        self.specs = {48: _lib.cat048(), 34: _lib.cat034()}
        self.categories = {int(c) for c in gen.manifest["CATS"]} | {34, 48}
        self.sites: dict[int, tuple[float, float, float, int]] = {}
        self.readers = {48: reader048(plot_row), 34: reader034(self._mark, self.sites)} \
            if fast else {}
        self.duplicates = DuplicateFilter() if duplicates is True else \
            (duplicates or None)
        self.restorer = TimeRestorer()
        self._judged: dict[tuple[int, bytes], list[Any]] = {}  # :meth:`fills`' records

    def blocks(self, payload: bytes, offset: int, problems: Problems,
               when: float | None = None
               ) -> Iterator[tuple[int, str, list[tuple[Any, ...]]]]:
        """``(file offset, kind, rows)`` of each data block of one unit (captured at
        ``when``, POSIX s or ``None``): kind :data:`PLOTS`, :data:`MARKS` or
        :data:`ADSB`, rows in record order; other blocks are counted in ``problems`` and
        skipped."""
        for at, cat, raw in blocks(payload, offset, problems):
            if cat not in (48, 34, 1, 2, 21):
                problems.add("unknown_category", at, detail=f"category {cat}")
                continue
            if self.duplicates is not None:
                start = at - offset
                if not self.duplicates.keep(payload[start:start + 3 + len(raw)], when):
                    problems.add("duplicate", at)
                    continue
            found = self._records(cat, raw, at, when, problems)
            if found is None:
                problems.add("undecodable", at, detail=f"category {cat}: records do "
                             "not fill the block")
                continue
            if cat in (34, 2):
                yield at, MARKS, found
            elif cat == 21:
                yield at, ADSB, _plots_only(found, cat, at, problems)
            else:
                yield at, PLOTS, _plots_only(found, cat, at, problems)

    def units(self, data: bytes, kind: str, name: str, problems: Problems
              ) -> Iterator[Unit]:
        """The units of recording ``data`` of framing ``kind``
        (:func:`~mhtrack.io.asterix.framings.units`) as every reader of a recording
        takes them — ``convert``, ``track``, ``replay``, a reference file: a raw
        stream's blocks judged by their content too (:meth:`fills`), so that a damaged
        file reads the same through each (``docs/file-formats.md``)."""
        return units(data, kind, name, self.categories, problems, self.fills)

    def fills(self, block: bytes) -> bool:
        """Whether the records of data block ``block`` (header included) fill it
        exactly: by this decoder's fast layouts (CAT048, CAT034) or its own reading of
        CAT001/002/021 (:data:`OWN_RECORDS`, through
        :func:`~mhtrack.io.asterix.fill.whole_records`: the records found are kept for
        the decoding, the last :data:`JUDGED_KEPT` blocks), else by any edition
        libasterix carries (:func:`~mhtrack.io.asterix.fill.fills_any_edition`)."""
        cat, raw = block[0], block[3:]
        if cat in self.readers and self.readers[cat].fills(raw):
            return True
        if cat in OWN_RECORDS and (recs := whole_records(raw, OWN_RECORDS[cat])) is not None:
            if len(self._judged) >= JUDGED_KEPT:
                del self._judged[next(iter(self._judged))]
            self._judged[cat, bytes(raw)] = recs
            return True
        return fills_any_edition(cat, raw)

    def _records(self, cat: int, raw: bytes, at: int, when: float | None,
                 problems: Problems) -> list[tuple[Any, ...]] | None:
        """The rows of one block's records (``None``: they do not fill the block)."""
        recs = self._judged.pop((cat, bytes(raw)), None) if self._judged else None
        if cat == 1:
            return block001(raw, at, when, self.restorer, problems, recs)
        if cat == 2:
            return block002(raw, self.restorer, recs)
        if cat == 21:
            return block021(raw, at, problems, recs)
        if cat in self.readers:
            return self.readers[cat].block(raw, at, problems)
        records = self.specs[cat].cv_uap.parse(self.bits(raw))
        if isinstance(records, ValueError):
            return None
        read = plot_row if cat == 48 else self._mark
        return [row for rec in records if (row := read(rec, at, problems)) is not None]

    def _mark(self, rec: Any, at: int, problems: Problems) -> tuple[Any, ...] | None:
        """A CAT034 record's sweep mark (:func:`mark_row`); its site to :attr:`sites`."""
        site_row(rec, at, self.sites)
        return mark_row(rec)


def _plots_only(rows: list[tuple[Any, ...]], cat: int, at: int, problems: Problems
                ) -> list[tuple[Any, ...]]:
    """The rows that are plots of real targets (:func:`~mhtrack.io.asterix.notplots.
    reason`), the others counted (``not_plot``, the first one's reason in the detail).
    Rows hold from column 11 on: CAT048 ``typ`` and the I048/020 flags (the plot type
    made here), then ``mode_3a_vg, flight_level_vg``, then the
    :data:`CHARACTERISTICS` when the record has I048/130; CAT001 ``typ, plot_type,
    mode_3a_vg, flight_level_vg, sim, rab, tst, track``, then the characteristics (all
    NaN but ``amplitude``) when it has I001/131; CAT021 ``typ, plot_type``, the
    validity bits (0), the flags, ``lat, lon, sigma``. The result has
    :data:`PLOT_COLUMNS` (CAT021: then ``lat, lon, sigma``)."""
    out, dropped, first = [], 0, ""
    for r in rows:
        if cat == 48:
            why = reason(r[11], r[12], r[13], r[14])
            row = (*r[:12], plot_type048_of(r[11]), r[15], r[16], *r[17:])
        elif cat == 1:
            why = reason(r[11], r[15], r[16], r[17], r[18])
            row = (*r[:15], *r[19:])  # I001/131: the characteristics' amplitude
        else:
            why = reason(-1, r[15], r[16], r[17])
            row = (*r[:11], -1, *r[12:15], *r[18:])
        if why is None:
            out.append(row)
        else:
            dropped += 1
            first = first or why
    if dropped:
        problems.add("not_plot", at, dropped, detail=f"first: {first}")
    return out


def sweep_periods(sweeps: dict[str, np.ndarray]) -> dict[int, float]:
    """Each radar's rotation period (s) from its CAT034 sweep marks (``time, sensor,
    kind, period`` columns): the median I034/041 if sent (and > 0), else the median
    interval between its north markers; radars with fewer than two north markers and no
    I034/041 are left out."""
    out: dict[int, float] = {}
    s = sweeps
    for sensor in np.unique(s["sensor"]).tolist():
        mine = s["sensor"] == sensor
        ars = s["period"][mine & np.isfinite(s["period"]) & (s["period"] > 0)]
        north = np.sort(s["time"][mine & (s["kind"] == 1)])
        if ars.size:
            out[int(sensor)] = float(np.median(ars))
        elif north.size >= 2:
            out[int(sensor)] = float(np.median(np.diff(north)))
    return out


def _sub(item: Any, name: str) -> Any:
    return item.variation.get_item(name)


def plot_row(rec: Any, at: int, problems: Problems) -> tuple[Any, ...] | None:
    """One report row from a CAT048 record — :data:`PLOT_COLUMNS` up to
    ``track_number``, then I048/020's ``typ, sim, rab, tst``
    (:func:`~mhtrack.io.asterix.notplots.flags048`), then the validity bits of 070 and
    090 (:data:`VG`) — or ``None`` (counted) without 040/140/010."""
    i040 = rec.get_item("040")
    if i040 is None:
        problems.add("no_position", at)
        return None
    i010, i140 = rec.get_item("010"), rec.get_item("140")
    if i010 is None or i140 is None:
        problems.add("no_time", at)
        return None
    sac = _sub(i010, "SAC").variation.content.as_uint()
    sic = _sub(i010, "SIC").variation.content.as_uint()
    rho = quantity(_sub(i040, "RHO"), "NM") * NM_M
    theta = quantity(_sub(i040, "THETA"), "°")
    i090, i070 = rec.get_item("090"), rec.get_item("070")
    fl = quantity(_sub(i090, "FL"), "FL") if i090 is not None else np.nan
    m3a = _sub(i070, "MODE3A").variation.content.as_string() if i070 is not None else ""
    i220, i240, i161 = rec.get_item("220"), rec.get_item("240"), rec.get_item("161")
    address = f"{i220.variation.content.as_uint():06X}" if i220 is not None else ""
    callsign = i240.variation.content.as_string().strip() if i240 is not None else ""
    tn = _sub(i161, "TRN").variation.content.as_uint() if i161 is not None else -1
    i130 = rec.get_item("130")
    return (quantity(i140, "s"), sac * 256 + sic, sac, sic, rho, theta, fl, m3a, address,
            callsign, tn, *flags048(rec), vg(i070), vg(i090),
            *(() if i130 is None else characteristics(i130)))



def vg(item: Any) -> int:
    """``2·V + G`` of a libasterix I048/070, /090 or I001/070, /090 (0 when absent)."""
    if item is None:
        return 0
    return 2 * _sub(item, "V").variation.content.as_uint() + \
        _sub(item, "G").variation.content.as_uint()


def site_row(rec: Any, at: int, sites: dict[int, tuple[float, float, float, int]]
             ) -> None:
    """Keep a CAT034 record's I034/120 (height m, WGS-84 lat, lon) in ``sites`` under its
    I034/010 data source, the first one sent (at byte ``at``)."""
    i010, i120 = rec.get_item("010"), rec.get_item("120")
    if i010 is None or i120 is None:
        return
    sensor = _sub(i010, "SAC").variation.content.as_uint() * 256 + \
        _sub(i010, "SIC").variation.content.as_uint()
    if sensor not in sites:
        sites[sensor] = (quantity(_sub(i120, "LAT"), "°"), quantity(_sub(i120, "LON"), "°"),
                         quantity(_sub(i120, "HGT"), "m"), at)


def mark_row(rec: Any) -> tuple[Any, ...] | None:
    """``(time of day, sensor, kind, azimuth, period)`` of a CAT034 north marker or
    sector crossing, or ``None`` for other messages or without I034/010, 030."""
    i000, i010, i030 = rec.get_item("000"), rec.get_item("010"), rec.get_item("030")
    if i000 is None or i010 is None or i030 is None:
        return None
    kind = i000.variation.content.as_uint()
    if kind not in (1, 2):
        return None
    sac = _sub(i010, "SAC").variation.content.as_uint()
    sic = _sub(i010, "SIC").variation.content.as_uint()
    i020, i041 = rec.get_item("020"), rec.get_item("041")
    azimuth = quantity(i020, "°") if i020 is not None and kind == 2 else np.nan
    period = quantity(i041, "s") if i041 is not None else np.nan
    return quantity(i030, "s"), sac * 256 + sic, kind, azimuth, period


def _columns(rows: list[tuple[Any, ...]], marks: list[tuple[Any, ...]],
             is_plot: np.ndarray, t: np.ndarray) -> tuple[dict[str, np.ndarray],
                                                          dict[str, np.ndarray]]:
    """Plot and sweep columns; ``t``: the axis time of every row and mark, in file order
    (``is_plot`` telling which is which)."""
    plots = plot_columns(rows)
    plots["time"] = t[is_plot] if t.size else np.zeros(0)
    mcols = list(zip(*marks, strict=True)) if marks else [()] * 5
    sweeps = {name: np.array(c, dtype=k) for name, c, k in zip(
        ("time", "sensor", "kind", "azimuth", "period"), mcols,
        (float, np.int64, np.int64, float, float), strict=True)}
    sweeps["time"] = t[~is_plot] if t.size else np.zeros(0)
    return plots, sweeps


def plot_columns(rows: list[tuple[Any, ...]]) -> dict[str, np.ndarray]:
    """:data:`PLOT_COLUMNS` of plot rows (:meth:`Decoder.blocks`), then :data:`ADSB_EXTRA`
    when a row is an ADS-B report, and :data:`CHARACTERISTICS` when a row has radar
    plot characteristics (NaN on the other rows); ``time`` is the time of day."""
    k = len(PLOT_COLUMNS)
    out = columns([r[:k] for r in rows], PLOT_COLUMNS)
    for names, width in ((ADSB_EXTRA, len(ADSB_EXTRA)), (CHARACTERISTICS, len(CHARACTERISTICS))):
        if any(len(r) == k + width for r in rows):
            extra = np.array([r[k:] if len(r) == k + width else (np.nan,) * width
                              for r in rows], float)
            out.update(zip(names, extra.T, strict=True))
    return out
