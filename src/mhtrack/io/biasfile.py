"""The registration-bias state file (``track --bias-out``, read back by ``--bias-init``):
one JSON object ``{"format": "mhtrack-bias", "version": 1, "reference": [ids],
"radars": {"<id>": {range_offset, range_gain, azimuth_deg, sigma_range_offset,
sigma_range_gain, sigma_azimuth_deg}}}`` (m, 1, degrees; ``docs/registration.md``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from os import PathLike

import numpy as np

from mhtrack.io.atomic import atomic_write
from mhtrack.io.jsonfile import key_error, kind_of, read_json_object
from mhtrack.io.jsonsafe import dumps
from mhtrack.models.registration import RadarBias

FORMAT, VERSION = "mhtrack-bias", 1
_FIELDS = ("range_offset", "range_gain", "azimuth_deg", "sigma_range_offset",
           "sigma_range_gain", "sigma_azimuth_deg")
#: Largest magnitude accepted per field (a range offset of 100 km, a gain within
#: [0.5, 2], an azimuth offset of 180°).
_LIMITS = {"range_offset": 1e5, "range_gain": 2.0, "azimuth_deg": 180.0,
           "sigma_range_offset": 1e5, "sigma_range_gain": 1.0, "sigma_azimuth_deg": 180.0}


def write_biases(path: str | PathLike[str], biases: Mapping[int, RadarBias],
                 reference: Sequence[int] = ()) -> None:
    """Write ``biases`` (radar id → estimate) atomically."""
    obj = {"format": FORMAT, "version": VERSION, "reference": [int(i) for i in reference],
           "radars": {str(sid): b.as_dict() for sid, b in sorted(biases.items())}}
    atomic_write(path, dumps(obj, indent=2) + "\n")


def read_biases(path: str | PathLike[str]) -> dict[int, RadarBias]:
    """The biases of a file :func:`write_biases` wrote; every field checked
    (:class:`~mhtrack.errors.InputError` naming the file and key)."""
    d = read_json_object(path, "registration biases", ("format", "radars"))
    if d["format"] != FORMAT:
        raise key_error(path, "format", f"expected {FORMAT!r}, got {d['format']!r}")
    radars = d["radars"]
    if not isinstance(radars, dict):
        raise key_error(path, "radars", f"expected an object, got {kind_of(radars)}")
    out: dict[int, RadarBias] = {}
    for sid, fields in radars.items():
        where = f"radars.{sid}"
        if not sid.lstrip("-").isdigit():
            raise key_error(path, where, "a radar id must be an integer")
        if not isinstance(fields, dict):
            raise key_error(path, where, f"expected an object, got {kind_of(fields)}")
        v = {}
        for k in _FIELDS:
            x = fields.get(k)
            if isinstance(x, bool) or not isinstance(x, int | float):
                raise key_error(path, f"{where}.{k}", f"expected a number, got {kind_of(x)}")
            if not (np.isfinite(x) and abs(x) <= _LIMITS[k]) or (k.startswith("sigma")
                                                                 and x < 0):
                raise key_error(path, f"{where}.{k}", f"{x!r} out of range (|x| <= "
                                f"{_LIMITS[k]:g}, σ >= 0)")
            v[k] = float(x)
        if not 0.5 <= v["range_gain"] <= 2.0:
            raise key_error(path, f"{where}.range_gain", f"{v['range_gain']} not in [0.5, 2]")
        out[int(sid)] = RadarBias(v["range_offset"], v["range_gain"], v["azimuth_deg"],
                                  (v["sigma_range_offset"], v["sigma_range_gain"],
                                   v["sigma_azimuth_deg"]))
    return out
