"""The dict (TOML) form of a rotating radar, both ways (``docs/scenarios.md``).

A ``[[sensors]]`` table of ``kind = "polar"`` with a ``period`` is a
:class:`~mhtrack.models.sensors.RotatingRadar`::

    kind = "polar"          id = 1            pd = 0.9
    lat = 51.4775           lon = -0.4614     # or position = [x, y] (local frame, m)
    sigma_range = 30.0      sigma_bearing_deg = 0.08
    period = 4.0            phase = 0.0       # beam bearing at t = 0 (optional, 0)
    max_range = 300000.0    clutter_rate = 20.0   # per rotation (optional, 0)
    range_bias = 200.0      range_gain = 1.0  azimuth_bias_deg = -0.12   # optional, none
    [[sensors.clutter_patches]]             # optional, any number
    range = 110000.0  bearing = 200.0  sigma_range = 15000.0  sigma_bearing_deg = 8.0
    rate = 8.0

Errors name the key path, e.g. ``sensors[1].clutter_patches[0].rate: must be >= 0.0``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from mhtrack.models.clutter import ClutterPatch
from mhtrack.models.sensors import MAX_SIGMA, MAX_SIGMA_BEARING_DEG, RotatingRadar
from mhtrack.records import MAX_COORDINATE
from mhtrack.scenario import _check as ck

BIAS_KEYS = ("range_bias", "range_gain", "azimuth_bias_deg")
_KEYS = {"kind", "id", "pd", "period", "sigma_range", "sigma_bearing_deg"}
_OPTIONAL = {"phase", "lat", "lon", "position", "max_range", "clutter_rate",
             "clutter_patches", *BIAS_KEYS}
#: The registration-bias keys of a simulated radar and their "no bias" values.
BIAS_DEFAULTS = {"range_bias": 0.0, "range_gain": 1.0, "azimuth_bias_deg": 0.0}
_PATCH_KEYS = {"range", "bearing", "sigma_range", "sigma_bearing_deg", "rate"}


def rotating_to_dict(s: RotatingRadar, pd: float) -> dict[str, Any]:
    """Dict form of a rotating radar with its detection probability ``pd``."""
    d: dict[str, Any] = {"kind": "polar", "id": int(s.id)}
    if s.lat is not None:
        d.update(lat=s.lat, lon=s.lon)
    else:
        d["position"] = [float(v) for v in s.position]  # type: ignore[union-attr]
    d.update(sigma_range=s.sigma_range, sigma_bearing_deg=s.sigma_bearing_deg, pd=float(pd),
             period=s.period, phase=s.phase)
    if s.max_range is not None:
        d["max_range"] = s.max_range
    d["clutter_rate"] = s.clutter_rate
    d.update({k: getattr(s, k) for k, v in BIAS_DEFAULTS.items() if getattr(s, k) != v})
    if s.clutter_patches:
        d["clutter_patches"] = [{k: getattr(p, k) for k in ("range", "bearing", "sigma_range",
                                                           "sigma_bearing_deg", "rate")}
                                for p in s.clutter_patches]
    return d


def rotating_from(d: Mapping[str, Any], path: str) -> tuple[RotatingRadar, float]:
    """A rotating radar and its ``pd`` from the dict form, every key validated."""
    ck.keys(d, path, _KEYS, _OPTIONAL)
    sid = ck.integer(d["id"], f"{path}.id", lo=0)
    kw: dict[str, Any] = {
        "period": ck.number(d["period"], f"{path}.period", lo=0.0, lo_open=True, unit="s"),
        "phase": ck.number(d.get("phase", 0.0), f"{path}.phase"),
        "sigma_range": ck.number(d["sigma_range"], f"{path}.sigma_range", lo=0.0,
                                 lo_open=True, hi=MAX_SIGMA, unit="m"),
        "sigma_bearing_deg": ck.number(d["sigma_bearing_deg"], f"{path}.sigma_bearing_deg",
                                       lo=0.0, lo_open=True, hi=MAX_SIGMA_BEARING_DEG,
                                       unit="degrees"),
        "clutter_rate": ck.number(d.get("clutter_rate", 0.0), f"{path}.clutter_rate", lo=0.0),
    }
    kw.update({k: ck.number(d[k], f"{path}.{k}") for k in BIAS_KEYS if k in d})
    if "max_range" in d:
        kw["max_range"] = ck.number(d["max_range"], f"{path}.max_range", lo=0.0,
                                    lo_open=True, hi=MAX_COORDINATE, unit="m")
    if "position" in d:
        if "lat" in d or "lon" in d:
            raise ValueError(f"{path}.position: give the site once: lat/lon or position")
        pos = ck.array(d["position"], f"{path}.position", (2,), MAX_COORDINATE)
        kw["position"] = (float(pos[0]), float(pos[1]))
    else:
        for key, lim in (("lat", 90.0), ("lon", 180.0)):
            if key not in d:
                raise ValueError(f"{path}.{key}: missing (the site: lat and lon, or position)")
            kw[key] = ck.number(d[key], f"{path}.{key}", lo=-lim, hi=lim, unit="degrees")
    raw = d.get("clutter_patches", [])
    if not isinstance(raw, list | tuple):
        raise ValueError(f"{path}.clutter_patches: expected a list, got {type(raw).__name__}")
    patches = []
    for i, p in enumerate(raw):
        pp = f"{path}.clutter_patches[{i}]"
        t = ck.table(p, pp)
        ck.keys(t, pp, _PATCH_KEYS)
        patches.append(ClutterPatch(
            range=ck.number(t["range"], f"{pp}.range", lo=0.0, hi=MAX_COORDINATE, unit="m"),
            bearing=ck.number(t["bearing"], f"{pp}.bearing"),
            sigma_range=ck.number(t["sigma_range"], f"{pp}.sigma_range", lo=0.0,
                                  lo_open=True, hi=MAX_COORDINATE, unit="m"),
            sigma_bearing_deg=ck.number(t["sigma_bearing_deg"], f"{pp}.sigma_bearing_deg",
                                        lo=0.0, lo_open=True, hi=360.0, unit="degrees"),
            rate=ck.number(t["rate"], f"{pp}.rate", lo=0.0)))
    with ck.at(path):
        radar = RotatingRadar(id=sid, clutter_patches=tuple(patches), **kw)
    return radar, ck.detection_probability(d["pd"], f"{path}.pd")
