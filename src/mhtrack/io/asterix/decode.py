"""CAT048 target reports and CAT034 service messages of a recording, decoded by
libasterix into columns (docs/file-formats.md, "ASTERIX recordings").

One plot per CAT048 record with I048/040 (measured position), I048/010 (data source) and
I048/140 (time of day); the others are counted and skipped. CAT034 north markers
(I034/000 = 1) and sector crossings (= 2) become the radars' sweep marks. Blocks of other
categories, and blocks whose records do not decode to exactly their length, are counted
and skipped (libasterix's strict parsing: the records must fill the block).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix.container import blocks, container, datagrams
from mhtrack.io.asterix.fast import reader034, reader048
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import TimeAxis

#: One nautical mile (m), the unit of I048/040 RHO.
NM_M = 1852.0
#: One flight level (m): 100 ft of 0.3048 m.
FL_M = 30.48

#: The plot columns, in output order (docs/file-formats.md).
PLOT_COLUMNS = ("time", "sensor", "sac", "sic", "slant_range", "bearing", "flight_level",
                "mode_3a", "address", "callsign", "track_number", "typ")


@dataclass
class Recording:
    """A decoded recording: ``plots`` (name -> array, :data:`PLOT_COLUMNS`; missing values
    NaN for floats, ``-1`` for ints, ``""`` for text), ``sweeps`` (``time, sensor, kind``
    1 north marker / 2 sector crossing, ``azimuth`` deg, NaN for north markers;
    ``period`` s from I034/041, NaN when absent), the container and the skipped parts."""

    name: str
    container: str
    plots: dict[str, np.ndarray]
    sweeps: dict[str, np.ndarray]
    problems: Problems = field(default_factory=Problems)

    def __len__(self) -> int:
        return int(self.plots["time"].size)

    def periods(self) -> dict[int, float]:
        """Each radar's rotation period (s) from its CAT034 messages
        (:func:`sweep_periods`)."""
        return sweep_periods(self.sweeps)


def read_recording(path: str | Path, *, fast: bool = True) -> Recording:
    """Decode the CAT048 plots and CAT034 sweep marks of a pcap, pcapng or raw ASTERIX
    file (recognised by content). Malformed parts are counted in ``problems`` (the caller
    warns); a file that is no recording raises :class:`~mhtrack.errors.InputError`.
    ``fast=False`` decodes every record with libasterix alone (the reference path of
    :mod:`~mhtrack.io.asterix.fast`). Times are on one monotonic axis
    (:mod:`~mhtrack.io.asterix.timeaxis`, capture times where the container has them)."""
    name = str(path)
    data = Path(path).read_bytes()
    decoder = Decoder(fast=fast)
    kind = container(data, name, decoder.categories)
    problems = Problems()
    rows: list[tuple[Any, ...]] = []
    marks: list[tuple[Any, ...]] = []
    is_plot: list[bool] = []
    times: list[float] = []
    axis = TimeAxis()
    for offset, payload, when in datagrams(data, kind, name, problems):
        for _, cat, found in decoder.blocks(payload, offset, problems):
            into = rows if cat == 48 else marks
            into.extend(found)
            is_plot.extend([cat == 48] * len(found))
            times.extend(axis.times_list([r[0] for r in found], when))
    plots, sweeps = _columns(rows, marks, np.array(is_plot, bool),
                             np.array(times, float))
    return Recording(name, kind, plots, sweeps, problems)


class Decoder:
    """Decodes the CAT048 plots and CAT034 sweep marks of data blocks, block by block
    (through :mod:`~mhtrack.io.asterix.fast` unless ``fast=False``)."""

    def __init__(self, *, fast: bool = True) -> None:
        base, gen = _lib.modules()
        self.bits = base.Bits.from_bytes
        self.specs = {48: _lib.cat048(), 34: _lib.cat034()}
        self.categories = {int(c) for c in gen.manifest["CATS"]} | {34, 48}
        self.readers = {48: reader048(plot_row), 34: reader034(mark_row)} if fast else {}

    def blocks(self, payload: bytes, offset: int, problems: Problems
               ) -> Iterator[tuple[int, int, list[tuple[Any, ...]]]]:
        """``(file offset, category, rows)`` of each CAT048 or CAT034 block of one
        datagram: plot rows (:func:`plot_row`) or sweep marks (:func:`mark_row`), in
        record order; other blocks are counted in ``problems`` and skipped."""
        for at, cat, raw in blocks(payload, offset, problems):
            if cat not in (48, 34):
                problems.add("unknown_category", at, detail=f"category {cat}")
                continue
            if cat in self.readers:
                found = self.readers[cat].block(raw, at, problems)
                if found is None:
                    problems.add("undecodable", at, detail=f"category {cat}: records do "
                                 "not fill the block")
                    continue
                yield at, cat, found
                continue
            records = self.specs[cat].cv_uap.parse(self.bits(raw))
            if isinstance(records, ValueError):
                problems.add("undecodable", at, detail=f"category {cat}: {records}")
                continue
            out = []
            for rec in records:
                row = plot_row(rec, at, problems) if cat == 48 else mark_row(rec)
                if row is not None:
                    out.append(row)
            yield at, cat, out


def sweep_periods(sweeps: dict[str, np.ndarray]) -> dict[int, float]:
    """Each radar's rotation period (s) from its CAT034 sweep marks (``time, sensor,
    kind, period`` columns): the median I034/041 if sent, else the median interval
    between its north markers; radars with fewer than two north markers and no I034/041
    are left out."""
    out: dict[int, float] = {}
    s = sweeps
    for sensor in np.unique(s["sensor"]).tolist():
        mine = s["sensor"] == sensor
        ars = s["period"][mine & np.isfinite(s["period"])]
        north = np.sort(s["time"][mine & (s["kind"] == 1)])
        if ars.size:
            out[int(sensor)] = float(np.median(ars))
        elif north.size >= 2:
            out[int(sensor)] = float(np.median(np.diff(north)))
    return out


def _q(item: Any, unit: str) -> float:
    return float(item.variation.content.as_quantity(unit))


def _sub(item: Any, name: str) -> Any:
    return item.variation.get_item(name)


def plot_row(rec: Any, at: int, problems: Problems) -> tuple[Any, ...] | None:
    """One plot row from a CAT048 record, or ``None`` (counted) without 040/140/010."""
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
    rho = _q(_sub(i040, "RHO"), "NM") * NM_M
    theta = _q(_sub(i040, "THETA"), "°")
    i090, i070 = rec.get_item("090"), rec.get_item("070")
    fl = _q(_sub(i090, "FL"), "FL") if i090 is not None else np.nan
    m3a = _sub(i070, "MODE3A").variation.content.as_string() if i070 is not None else ""
    i220, i240, i161 = rec.get_item("220"), rec.get_item("240"), rec.get_item("161")
    address = f"{i220.variation.content.as_uint():06X}" if i220 is not None else ""
    callsign = i240.variation.content.as_string().strip() if i240 is not None else ""
    tn = _sub(i161, "TRN").variation.content.as_uint() if i161 is not None else -1
    i020 = rec.get_item("020")
    typ = -1
    if i020 is not None and (t := i020.variation.get_item("TYP")) is not None:
        typ = t.variation.content.as_uint()
    return (_q(i140, "s"), sac * 256 + sic, sac, sic, rho, theta, fl, m3a, address,
            callsign, tn, typ)


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
    azimuth = _q(i020, "°") if i020 is not None and kind == 2 else np.nan
    period = _q(i041, "s") if i041 is not None else np.nan
    return _q(i030, "s"), sac * 256 + sic, kind, azimuth, period


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
    """:data:`PLOT_COLUMNS` of plot rows (:func:`plot_row`); ``time`` is the time of day."""
    kinds = (float, np.int64, np.int64, np.int64, float, float, float, object, object,
             object, np.int64, np.int64)
    cols = list(zip(*rows, strict=True)) if rows else [()] * len(PLOT_COLUMNS)
    return {name: np.array(c, dtype=k) for name, c, k in zip(PLOT_COLUMNS, cols, kinds,
                                                             strict=True)}
