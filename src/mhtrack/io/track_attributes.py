"""The optional attribute columns of a tracks file (docs/file-formats.md, "Track
attributes"), written when the plots had attributes and read back into
:class:`~mhtrack.attributes.TrackAttributes`.

``flight_level`` (FL) and ``rate_of_climb`` (ft/min), ``mode_3a`` four octal digits,
``address`` six hexadecimal digits, ``callsign`` text, ``sigma_major``, ``sigma_minor``
(m) and ``sigma_orient`` (degrees from grid north, clockwise, [0, 180)), ``sensors``
(ids joined by ``;``) and ``sensor_ages`` (seconds, the same order), ``age_psr``,
``age_ssr``, ``age_mds`` (seconds since the last update of each technology), and the
row's plot's measurements ``meas_sensor``, ``meas_type`` (plot type name),
``meas_mode_3a``, ``meas_mode_3a_vg``, ``meas_flight_level``, ``meas_flight_level_vg``,
``meas_range`` (m), ``meas_bearing`` (degrees), and
``existence_probability`` (``1/(1 + e^−L)`` of the row's score). Empty cells
(Parquet nulls) are absent values; every column is written once any is, so that a file's
columns do not depend on its rows.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

from mhtrack.attributes import (
    PLOT_TYPES,
    TRACK_COLUMNS,
    TrackAttributes,
    address_text,
    address_value,
    code_text,
    code_value,
)
from mhtrack.io._checks import num
from mhtrack.io._frame import FLOAT, INT, TIME, Frame, float_array, int_array
from mhtrack.io.plot_attributes import _parsed, _text, _type_code

_NUMBERS = ("flight_level", "rate_of_climb", "sigma_major", "sigma_minor", "sigma_orient",
            "age_psr", "age_ssr", "age_mds", "meas_flight_level", "meas_range", "meas_bearing",
            "existence_probability")
#: Integer columns and their absent value (written as an empty cell).
_INTS = {"meas_sensor": -1, "meas_mode_3a_vg": 0, "meas_flight_level_vg": 0}
#: Column kinds for :func:`~mhtrack.io._frame.read_frame` (TIME: read as text).
KINDS = dict.fromkeys(_NUMBERS, FLOAT) | dict.fromkeys(_INTS, INT) | dict.fromkeys(
    ("mode_3a", "address", "callsign", "sensors", "sensor_ages", "meas_type",
     "meas_mode_3a"), TIME)


def track_attribute_columns(a: TrackAttributes) -> dict[str, pa.Array]:
    """The columns of ``a`` in :data:`~mhtrack.attributes.TRACK_COLUMNS` order, absent
    values as empty cells."""
    out: dict[str, pa.Array] = {}
    for name in TRACK_COLUMNS:
        v = getattr(a, name)
        if name in _NUMBERS:
            out[name] = float_array(v, nan_as_null=True)
        elif name in _INTS:
            out[name] = int_array(v, v == _INTS[name] if name == "meas_sensor" else
                                  np.asarray(a.meas_sensor) < 0)
        elif name == "meas_type":
            out[name] = _strings(["" if c <= 0 else PLOT_TYPES[int(c)] for c in v.tolist()])
        elif name in ("mode_3a", "meas_mode_3a"):
            out[name] = _strings([code_text(c) for c in v.tolist()])
        elif name == "address":
            out[name] = _strings([address_text(c) for c in v.tolist()])
        else:
            out[name] = _strings([str(c) for c in v.tolist()])
    return out


def _strings(values: list[str]) -> pa.Array:
    return pa.array(values, pa.string(), mask=np.array([v == "" for v in values], bool))


def read_track_attributes(f: Frame) -> TrackAttributes | None:
    """The attribute columns of a tracks file ``f`` (the others absent), ``None`` when it
    has none; a located :class:`~mhtrack.errors.InputError` for the first bad cell."""
    if not any(f.has(c) for c in TRACK_COLUMNS):
        return None
    out = TrackAttributes.absent(f.n)
    cols = {name: getattr(out, name) for name in TRACK_COLUMNS}
    for name in _NUMBERS:
        if f.has(name):
            cols[name] = f.floats(name, nullable=True)
    sig = cols["sigma_major"], cols["sigma_minor"]
    for v, name in zip(sig, ("sigma_major", "sigma_minor"), strict=True):
        f.check(v < 0, name, lambda r, v=v: f"σ {num(v[r])} m is negative")
    f.check(cols["sigma_minor"] > cols["sigma_major"], "sigma_minor",
            lambda r: f"σ minor {num(sig[1][r])} m exceeds σ major {num(sig[0][r])} m")
    for name in ("age_psr", "age_ssr", "age_mds"):
        v = cols[name]
        f.check(v < 0, name, lambda r, v=v: f"age {num(v[r])} s is negative")
    mr, mb = cols["meas_range"], cols["meas_bearing"]
    f.check(mr < 0, "meas_range", lambda r: f"range {num(mr[r])} m is negative")
    f.check((mb < 0) | (mb >= 360), "meas_bearing",
            lambda r: f"bearing {num(mb[r])}° is outside [0, 360)")
    p = cols["existence_probability"]
    f.check((p < 0) | (p > 1), "existence_probability",
            lambda r: f"probability {num(p[r])} is outside [0, 1]")
    o = cols["sigma_orient"]
    f.check((o < 0) | (o >= 180), "sigma_orient",
            lambda r: f"orientation {num(o[r])}° is outside [0, 180)")
    for name, parse in (("mode_3a", code_value), ("address", address_value),
                        ("meas_mode_3a", code_value), ("meas_type", _type_code)):
        if f.has(name):
            cols[name] = _parsed(f, name, parse)
    for name, absent in _INTS.items():
        if f.has(name):
            cols[name] = f.ints(name, nullable=True, fill=absent)
    for name in ("meas_mode_3a_vg", "meas_flight_level_vg"):
        v = cols[name]
        f.check((v < 0) | (v > 3), name, lambda r, v=v: f"validity {v[r]} is not 2·V + G "
                "(0 to 3)")
    for name in ("callsign", "sensors", "sensor_ages"):
        if f.has(name):
            cols[name] = np.array(_text(f, name), object)
    _check_ages(f, cols["sensors"], cols["sensor_ages"])
    return TrackAttributes(**cols)


def _check_ages(f: Frame, sensors: np.ndarray, ages: np.ndarray) -> None:
    """``sensors`` non-negative integers and ``sensor_ages`` as many non-negative numbers,
    both joined by ``;`` (located errors)."""
    def bad(r: int) -> str | None:
        s = [v for v in str(sensors[r]).split(";") if v != ""]
        a = [v for v in str(ages[r]).split(";") if v != ""]
        if not all(v.isdigit() for v in s):
            return f"sensors {sensors[r]!r} are not ids joined by ';'"
        try:
            nums = [float(v) for v in a]
        except ValueError:
            return f"sensor_ages {ages[r]!r} are not numbers joined by ';'"
        if len(nums) != len(s) or any(not v >= 0 for v in nums):
            return f"sensor_ages {ages[r]!r}: one age >= 0 s per sensor of {sensors[r]!r}"
        return None

    problems = [bad(r) for r in range(len(sensors))]
    f.check(np.array([p is not None for p in problems], bool), "sensor_ages",
            lambda r: str(problems[r]))
