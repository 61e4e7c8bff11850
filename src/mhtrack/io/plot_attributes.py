"""The optional attribute columns of a plots file (docs/file-formats.md, "Plot
attributes"): read with located errors into :class:`~mhtrack.attributes.PlotAttributes`,
and written back.

Text columns as ``mhtrack convert`` writes them: ``plot_type`` a name of
:data:`~mhtrack.attributes.PLOT_TYPES` (``primary``, ``secondary``, ``combined``,
``mode_s``; empty or ``none`` unknown), ``mode_3a`` four octal digits, ``address`` six
hexadecimal digits, ``callsign`` text; numbers ``flight_level`` (FL) and ``amplitude``
(dBm); flags ``mode_3a_v``, ``mode_3a_g``, ``flight_level_v``, ``flight_level_g`` 0 or 1
(ASTERIX's V "not validated" and G "garbled" bits; empty = 0). Empty cells are absent
values.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

from mhtrack.attributes import (
    COLUMNS,
    PLOT_TYPES,
    PlotAttributes,
    address_text,
    address_value,
    code_text,
    code_value,
)
from mhtrack.io._frame import FLOAT, INT, TIME, Frame, float_array, int_array
from mhtrack.io.asterix.earth import slant_range

#: Column kinds for :func:`~mhtrack.io._frame.read_frame` (TIME: read as text).
KINDS = {"plot_type": TIME, "mode_3a": TIME, "mode_3a_v": INT, "mode_3a_g": INT,
         "flight_level": FLOAT, "flight_level_v": INT, "flight_level_g": INT,
         "address": TIME, "callsign": TIME, "amplitude": FLOAT}
#: Flight levels a file may give (I048/090 holds −12 to 1 270 FL).
FL_RANGE = (-12.0, 1270.0)
#: Metres per flight level (100 ft).
FL_M = 30.48
_TYPE_CODE = {name: code for code, name in PLOT_TYPES.items()}


def read_attributes(f: Frame, order: np.ndarray | None = None,
                    polar: tuple[np.ndarray, np.ndarray] | None = None,
                    site: tuple[np.ndarray, np.ndarray] | None = None
                    ) -> PlotAttributes | None:
    """The attribute columns of ``f`` (rows in file order, then taken in ``order`` when
    given), ``None`` when the file has none. Raises a located
    :class:`~mhtrack.errors.InputError` for the first bad cell.

    ``polar``: the file's checked ``(range, bearing)`` columns (ground range, NaN on
    Cartesian rows). The measured position kept (:data:`~mhtrack.attributes.POLAR`, as
    ASTERIX I048/040 gives it) is the SLANT range: :func:`slant_of_ground` of the row's
    flight level and ``site`` (per-row latitude and altitude, NaN where unknown); NaN
    without a flight level."""
    if not any(f.has(c) for c in COLUMNS):
        return None
    cols: dict[str, np.ndarray] = {}
    for name in ("mode_3a_v", "mode_3a_g", "flight_level_v", "flight_level_g"):
        if f.has(name):
            v = f.ints(name, nullable=True, fill=0)
            f.check((v != 0) & (v != 1), name, lambda r, v=v: f"flag {v[r]} is not 0 or 1")
            cols[name] = v
    if f.has("flight_level"):
        h = f.floats("flight_level", nullable=True)
        f.check((h < FL_RANGE[0]) | (h > FL_RANGE[1]), "flight_level",
                lambda r: f"flight level {h[r]:g} is outside {FL_RANGE[0]:g} to "
                f"{FL_RANGE[1]:g} FL")
        cols["flight_level"] = h
    if f.has("amplitude"):
        cols["amplitude"] = f.floats("amplitude", nullable=True)
    for name, parse in (("mode_3a", code_value), ("address", address_value),
                        ("plot_type", _type_code)):
        if f.has(name):
            cols[name] = _parsed(f, name, parse)
    if f.has("callsign"):
        cols["callsign"] = np.array([s or "" for s in _text(f, "callsign")], object)
    if polar is not None:  # polar plots: their measured position (slant, as I048/040)
        ground, bearing = (np.asarray(v, float) for v in polar)
        level = cols.get("flight_level", np.full(f.n, np.nan))
        cols["polar_range"] = slant_of_ground(ground, bearing, level, *(
            site if site is not None else (np.full(f.n, np.nan), np.zeros(f.n))))
        cols["polar_bearing"] = bearing
    out = PlotAttributes.from_columns(cols, f.n)
    return out if order is None else out.take(order)


def slant_of_ground(ground: np.ndarray, bearing: np.ndarray, flight_level: np.ndarray,
                    site_lat: np.ndarray, site_alt: np.ndarray) -> np.ndarray:
    """Slant range (m) of ground ranges to targets at ``flight_level`` (FL, 30.48 m each)
    from sites at ``site_lat`` (°) and ``site_alt`` (m, NaN taken as 0):
    :func:`mhtrack.io.asterix.earth.slant_range` on the ellipsoid where the latitude is
    known, else in the plane ``ρ = √(s² + Δh²)`` (a scenario's flat frame); NaN where the
    flight level is unknown."""
    g = np.asarray(ground, float)
    h = np.asarray(flight_level, float) * FL_M
    lat = np.broadcast_to(np.asarray(site_lat, float), g.shape)
    alt = np.nan_to_num(np.broadcast_to(np.asarray(site_alt, float), g.shape))
    out = np.hypot(g, h - alt)
    geo = np.isfinite(lat)
    if geo.any():
        out[geo] = slant_range(g[geo], np.asarray(bearing, float)[geo], h[geo], lat[geo],
                               alt[geo])
    return out


def _text(f: Frame, name: str) -> list[str]:
    """Column ``name`` as text ("" for an empty cell; Parquet numbers as written)."""
    return ["" if v is None else str(v).strip() for v in f.table.column(name).to_pylist()]


def _parsed(f: Frame, name: str, parse: object) -> np.ndarray:
    """Each distinct text of column ``name`` parsed once (``parse``: text → int, a
    ``ValueError`` for a bad cell, located)."""
    text = np.array(_text(f, name), object)
    values, inverse = np.unique(text.astype(str), return_inverse=True)
    out = np.empty(values.size, np.int64)
    for i, s in enumerate(values.tolist()):
        try:
            out[i] = parse(s)  # type: ignore[operator]
        except ValueError as e:
            f.fail(str(e), row=int(np.argmax(inverse == i)), column=name)
    return out[inverse.reshape(-1)]


def _type_code(text: str) -> int:
    if text == "":
        return 0
    if text not in _TYPE_CODE:
        raise ValueError(f"plot type {text!r} is not one of {', '.join(_TYPE_CODE)}")
    return _TYPE_CODE[text]


def attribute_columns(attrs: PlotAttributes, order: np.ndarray | slice = slice(None)
                      ) -> dict[str, pa.Array]:
    """The columns to write (rows ``order``), absent values as empty cells; the flags
    only where one is set, the text columns only where one is given."""
    a = attrs.take(order)
    out: dict[str, pa.Array] = {}
    if (a.plot_type > 0).any():
        out["plot_type"] = pa.array([PLOT_TYPES.get(int(k), "none") if k > 0 else None
                                     for k in a.plot_type.tolist()], pa.string())
    if (a.mode_3a >= 0).any():
        out["mode_3a"] = _strings([code_text(v) for v in a.mode_3a.tolist()])
    for name in ("mode_3a_v", "mode_3a_g"):
        if (getattr(a, name) != 0).any():
            out[name] = int_array(getattr(a, name))
    if np.isfinite(a.flight_level).any():
        out["flight_level"] = float_array(a.flight_level, nan_as_null=True)
    for name in ("flight_level_v", "flight_level_g"):
        if (getattr(a, name) != 0).any():
            out[name] = int_array(getattr(a, name))
    if (a.address >= 0).any():
        out["address"] = _strings([address_text(v) for v in a.address.tolist()])
    if any(a.callsign.tolist()):
        out["callsign"] = _strings([str(s) for s in a.callsign.tolist()])
    if np.isfinite(a.amplitude).any():
        out["amplitude"] = float_array(a.amplitude, nan_as_null=True)
    return out


def _strings(values: list[str]) -> pa.Array:
    return pa.array(values, pa.string(), mask=np.array([v == "" for v in values], bool))


def decoded_attributes(p: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The attribute columns (:data:`~mhtrack.attributes.COLUMNS`, codes and addresses as
    integers) of decoded ASTERIX plot columns (:data:`mhtrack.io.asterix.decode.
    PLOT_COLUMNS`: ``mode_3a`` octal and ``address`` hexadecimal text, the validity bits
    as ``2·V + G``), and the measured slant range and bearing as
    :data:`~mhtrack.attributes.POLAR`."""
    n = len(p["time"])
    out: dict[str, np.ndarray] = {
        "plot_type": np.asarray(p.get("plot_type", np.zeros(n, np.int64)), np.int64),
        "flight_level": np.asarray(p.get("flight_level", np.full(n, np.nan)), float),
        "callsign": np.asarray(p.get("callsign", np.full(n, "", object)), object),
        "amplitude": np.asarray(p.get("amplitude", np.full(n, np.nan)), float),
    }
    for name, parse in (("mode_3a", code_value), ("address", address_value)):
        text = np.asarray(p.get(name, np.full(n, "", object)), object).astype(str)
        values, inverse = np.unique(text, return_inverse=True)
        out[name] = np.array([parse(s) for s in values.tolist()],
                             np.int64)[inverse.reshape(-1)] if n else np.zeros(0, np.int64)
    for base in ("mode_3a", "flight_level"):
        vg = np.asarray(p.get(f"{base}_vg", np.zeros(n, np.int64)), np.int64)
        out[f"{base}_v"], out[f"{base}_g"] = (vg >> 1) & 1, vg & 1
    if "slant_range" in p and "bearing" in p:  # the measured position (I048/040)
        out["polar_range"] = np.asarray(p["slant_range"], float)
        out["polar_bearing"] = np.asarray(p["bearing"], float)
    return out
