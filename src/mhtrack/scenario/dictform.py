"""The dict (TOML) form of a scenario's parts, both ways: to plain dicts, and from them
with every key validated.

The dict form (``docs/scenarios.md``) is made of tables, lists, strings and numbers only,
so it can be written to TOML as is. Reading rejects unknown keys, wrong types and
non-finite numbers with a ``ValueError`` naming the key path, e.g. ``targets[2].birth:
must be <= death (50 > 40)``; :func:`scenario_fields` returns the validated fields that
:class:`~mhtrack.scenario.spec.Scenario` is built from.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from mhtrack.bounds import MAX_SEED
from mhtrack.models.clutter import (
    GaussianMixtureClutter,
    Region,
    TimeVaryingClutter,
    UniformClutter,
)
from mhtrack.models.sensors import (
    MAX_SIGMA,
    MAX_SIGMA_BEARING_DEG,
    CartesianSensor,
    PolarRadar,
    RotatingRadar,
    Sensor,
)
from mhtrack.records import MAX_COORDINATE
from mhtrack.scenario import _check as ck
from mhtrack.scenario.limits import (
    MAX_T,
    check_period,
    check_scan_range,
    check_sigma_v,
    check_state,
)
from mhtrack.scenario.radardict import rotating_from, rotating_to_dict
from mhtrack.scenario.targets import AnyTarget, RecordedTarget, Target

ClutterSpec = UniformClutter | GaussianMixtureClutter | TimeVaryingClutter

#: Clutter kinds of the dict form.
CLUTTER_KINDS = ("uniform", "gmm", "time-varying")
#: Sensor kinds of the dict form.
SENSOR_KINDS = ("cartesian", "polar")


# ---------------------------------------------------------------------- to dict
def region_to_dict(r: Region) -> dict[str, float]:
    """``{xmin, xmax, ymin, ymax}`` of a region."""
    return {
        "xmin": float(r.xmin),
        "xmax": float(r.xmax),
        "ymin": float(r.ymin),
        "ymax": float(r.ymax),
    }


def sensor_to_dict(s: Sensor, pd: float) -> dict[str, Any]:
    """Dict form of a sensor with its detection probability ``pd``."""
    if isinstance(s, RotatingRadar):
        return rotating_to_dict(s, pd)
    if isinstance(s, PolarRadar):
        return {
            "kind": "polar",
            "id": int(s.id),
            "position": [float(v) for v in s.position],
            "sigma_range": float(s.sigma_range),
            "sigma_bearing_deg": float(s.sigma_bearing_deg),
            "pd": float(pd),
        }
    return {"kind": "cartesian", "id": int(s.id), "sigma": float(s.sigma), "pd": float(pd)}


def target_to_dict(t: AnyTarget) -> dict[str, Any]:
    """Dict form of a constant-velocity or recorded target."""
    if isinstance(t, RecordedTarget):
        return {"id": t.id, "scans": list(t.scans), "states": [list(s) for s in t.states]}
    return {"id": t.id, "state": list(t.state), "birth": t.birth, "death": t.death}


def _mixture_to_dict(m: GaussianMixtureClutter) -> dict[str, Any]:
    return {
        "rate": float(m.rate_per_scan),
        "weights": np.asarray(m.weights, float).tolist(),
        "means": np.asarray(m.means, float).tolist(),
        "covariances": np.asarray(m.covariances, float).tolist(),
        "background": float(m.background),
    }


def clutter_to_dict(c: ClutterSpec) -> dict[str, Any]:
    """Dict form of a clutter model (its region is the scenario's and is not written)."""
    if isinstance(c, UniformClutter):
        return {"kind": "uniform", "rate": float(c.rate_per_scan)}
    if isinstance(c, GaussianMixtureClutter):
        return {"kind": "gmm", **_mixture_to_dict(c)}
    if isinstance(c, TimeVaryingClutter):
        return {
            "kind": "time-varying",
            "keyframes": [{"scan": int(k), **_mixture_to_dict(m)} for k, m in c.keyframes],
        }
    raise ValueError(f"clutter: cannot write a {type(c).__name__}")


# ---------------------------------------------------------------------- from dict
_TOP_REQUIRED = {"T", "scans", "region", "sensors"}
_TOP_OPTIONAL = {"name", "description", "targets", "truth_sigma_v", "seed", "clutter",
                 "origin", "truth_dt", "clutter_scene"}


def scenario_fields(d: Mapping[str, Any]) -> dict[str, Any]:
    """The fields of a :class:`~mhtrack.scenario.spec.Scenario` (keyword arguments) from its
    dict form, validating every key.

    Target ``birth`` / ``death`` may be left out: they default to the first / last scan.
    An optional top-level ``seed`` (integer ``>= 0``, what the CLI records next to the
    parameters in ``scenario.toml``) is validated and otherwise ignored: a seed belongs to
    a simulation, not to a scenario.
    Raises ``ValueError`` whose message starts with the offending key path (the
    scenario's own checks, e.g. unique ids, run when it is built from these fields).
    """
    d = ck.table(d, "")
    raw = d.get("sensors")
    rotating = isinstance(raw, list | tuple) and any(
        isinstance(x, Mapping) and "period" in x for x in raw)
    # rotating radars draw their own clutter: the region's model is optional then
    ck.keys(d, "", _TOP_REQUIRED | (set() if rotating else {"clutter"}), _TOP_OPTIONAL)
    if "seed" in d:
        ck.integer(d["seed"], "seed", lo=0, hi=MAX_SEED)
    name = ck.string(d.get("name", "custom"), "name")
    description = ck.string(d.get("description", ""), "description")
    T = check_period(d["T"])
    sigma_v = check_sigma_v(d.get("truth_sigma_v", 0.0))
    scans = d["scans"]
    if not isinstance(scans, list | tuple) or len(scans) != 2:
        raise ValueError(f"scans: expected [first, last], got {scans!r}")
    first, last = check_scan_range(scans[0], scans[1])
    region = _region_from(d["region"], "region")

    raw_sensors = _list(d["sensors"], "sensors")
    sensors, pds = [], []
    for i, s in enumerate(raw_sensors):
        sensor, p = _sensor_from(s, f"sensors[{i}]")
        sensors.append(sensor)
        pds.append(p)
    targets = [
        _target_from(t, f"targets[{i}]", first, last)
        for i, t in enumerate(_list(d.get("targets", []), "targets"))
    ]
    if "clutter" in d:
        clutter = _clutter_from(d["clutter"], "clutter", region)
    else:
        clutter = UniformClutter(region, 0.0)
    extra: dict[str, Any] = {}
    if "origin" in d:
        o = ck.table(d["origin"], "origin")
        ck.keys(o, "origin", {"lat", "lon"})
        extra["origin"] = (ck.number(o["lat"], "origin.lat", lo=-90.0, hi=90.0, unit="degrees"),
                           ck.number(o["lon"], "origin.lon", lo=-180.0, hi=180.0,
                                     unit="degrees"))
    if "clutter_scene" in d:
        from mhtrack.scenario.scenedict import scene_from_dict

        extra["clutter_scene"] = scene_from_dict(d["clutter_scene"])
    if "truth_dt" in d:
        extra["truth_dt"] = ck.number(d["truth_dt"], "truth_dt", lo=0.0, lo_open=True, hi=MAX_T,
                                      unit="s")
    return {
        **extra,
        "name": name,
        "description": description,
        "region": region,
        "T": T,
        "scans": (first, last),
        "sensors": tuple(sensors),
        "pd": tuple(pds),
        "clutter": clutter,
        "targets": tuple(targets),
        "truth_sigma_v": sigma_v,
    }


def _list(v: object, path: str) -> list[Any]:
    if not isinstance(v, list | tuple):
        raise ValueError(f"{path}: expected a list, got {type(v).__name__}")
    return list(v)


def _region_from(v: object, path: str) -> Region:
    d = ck.table(v, path)
    ck.keys(d, path, {"xmin", "xmax", "ymin", "ymax"})
    x0, x1, y0, y1 = (
        ck.bounded(d[k], ck.join(path, k), MAX_COORDINATE) for k in ("xmin", "xmax", "ymin", "ymax")
    )
    if x1 <= x0:
        raise ValueError(f"{path}.xmax: must be > xmin ({x1} <= {x0})")
    if y1 <= y0:
        raise ValueError(f"{path}.ymax: must be > ymin ({y1} <= {y0})")
    return Region(x0, x1, y0, y1)


def _kind(d: Mapping[str, Any], path: str, kinds: tuple[str, ...]) -> str:
    if "kind" not in d:
        raise ValueError(f"{path}.kind: missing (expected {', '.join(kinds)})")
    k = ck.string(d["kind"], f"{path}.kind")
    if k not in kinds:
        raise ValueError(f"{path}.kind: unknown {k!r} (expected {', '.join(kinds)})")
    return k


def _sensor_from(v: object, path: str) -> tuple[Sensor, float]:
    d = ck.table(v, path)
    kind = _kind(d, path, SENSOR_KINDS)
    if kind == "polar" and "period" in d:
        return rotating_from(d, path)
    if kind == "cartesian":
        ck.keys(d, path, {"kind", "id", "sigma", "pd"})
        sid = ck.integer(d["id"], f"{path}.id", lo=0)
        sigma = ck.number(d["sigma"], f"{path}.sigma", lo=0.0, lo_open=True, hi=MAX_SIGMA, unit="m")
        sensor: Sensor = CartesianSensor(id=sid, sigma=sigma)
    else:
        ck.keys(d, path, {"kind", "id", "position", "sigma_range", "sigma_bearing_deg", "pd"})
        sid = ck.integer(d["id"], f"{path}.id", lo=0)
        pos = ck.array(d["position"], f"{path}.position", (2,), MAX_COORDINATE)
        sr = ck.number(
            d["sigma_range"], f"{path}.sigma_range", lo=0.0, lo_open=True, hi=MAX_SIGMA, unit="m"
        )
        sb = ck.number(
            d["sigma_bearing_deg"],
            f"{path}.sigma_bearing_deg",
            lo=0.0,
            lo_open=True,
            hi=MAX_SIGMA_BEARING_DEG,
            unit="degrees",
        )
        sensor = PolarRadar(sid, (float(pos[0]), float(pos[1])), sr, sb)
    return sensor, ck.detection_probability(d["pd"], f"{path}.pd")


def _target_from(v: object, path: str, first: int, last: int) -> AnyTarget:
    d = ck.table(v, path)
    if "scans" in d or "states" in d:
        ck.keys(d, path, {"id", "scans", "states"})
        tid = ck.integer(d["id"], f"{path}.id", lo=0)
        raw = _list(d["scans"], f"{path}.scans")
        sc = [ck.integer(s, f"{path}.scans[{i}]", lo=0) for i, s in enumerate(raw)]
        if not sc:
            raise ValueError(f"{path}.scans: must not be empty")
        for i in range(1, len(sc)):
            if sc[i] <= sc[i - 1]:
                raise ValueError(
                    f"{path}.scans[{i}]: must be > the previous scan ({sc[i]} <= {sc[i - 1]})"
                )
        st = ck.array(d["states"], f"{path}.states", (len(sc), 4), magnitude=False)
        for i, row in enumerate(st):
            check_state(row, f"{path}.states[{i}]")
        with ck.at(path):
            return RecordedTarget(tid, tuple(sc), tuple(map(tuple, st.tolist())))
    ck.keys(d, path, {"id", "state"}, {"birth", "death"})
    tid = ck.integer(d["id"], f"{path}.id", lo=0)
    state = ck.array(d["state"], f"{path}.state", (4,), magnitude=False)
    check_state(state, f"{path}.state")
    birth = ck.integer(d.get("birth", first), f"{path}.birth", lo=0)
    death = ck.integer(d.get("death", last), f"{path}.death", lo=0)
    with ck.at(path):
        return Target(tid, tuple(state.tolist()), birth, death)


#: Smallest eigenvalue ratio of a clutter covariance; scipy's normal distribution treats a
#: covariance below about 2e-10 as singular.
_MIN_EIG_RATIO = 1e-9
_MIX_KEYS = {"rate", "weights", "means", "covariances"}


def _mixture_from(
    d: Mapping[str, Any], path: str, region: Region, ncomp: int | None = None
) -> GaussianMixtureClutter:
    rate = ck.number(d["rate"], f"{path}.rate", lo=0.0)
    w = ck.array(d["weights"], f"{path}.weights", (ncomp,))
    k = len(w)
    if k == 0:
        raise ValueError(f"{path}.weights: at least one component is needed")
    for i, wi in enumerate(w):
        if wi < 0:
            raise ValueError(f"{path}.weights[{i}]: must be >= 0, got {wi}")
    if w.sum() <= 0:
        raise ValueError(f"{path}.weights: must have a positive sum")
    mu = ck.array(d["means"], f"{path}.means", (k, 2))
    cov = ck.array(d["covariances"], f"{path}.covariances", (k, 2, 2))
    for i, c in enumerate(cov):
        eig = np.linalg.eigvalsh(0.5 * (c + c.T))
        if abs(c[0, 1] - c[1, 0]) > 1e-9 * max(abs(eig).max(), 1e-300) or eig[0] <= 0:
            raise ValueError(
                f"{path}.covariances[{i}]: must be symmetric positive definite, got {c.tolist()}"
            )
        if eig[0] <= _MIN_EIG_RATIO * eig[1]:
            raise ValueError(
                f"{path}.covariances[{i}]: too ill-conditioned (eigenvalues "
                f"{eig.tolist()}, ratio must exceed {_MIN_EIG_RATIO})"
            )
    bg = ck.probability(d.get("background", 0.0), f"{path}.background")
    with ck.at(path):
        return GaussianMixtureClutter(region, rate, w, mu, cov, background=bg)


def _clutter_from(v: object, path: str, region: Region) -> ClutterSpec:
    d = ck.table(v, path)
    kind = _kind(d, path, CLUTTER_KINDS)
    if kind == "uniform":
        ck.keys(d, path, {"kind", "rate"})
        return UniformClutter(region, ck.number(d["rate"], f"{path}.rate", lo=0.0))
    if kind == "gmm":
        ck.keys(d, path, {"kind"} | _MIX_KEYS, {"background"})
        return _mixture_from(d, path, region)
    ck.keys(d, path, {"kind", "keyframes"})
    frames = _list(d["keyframes"], f"{path}.keyframes")
    if not frames:
        raise ValueError(f"{path}.keyframes: at least one keyframe is needed")
    out: list[tuple[int, GaussianMixtureClutter]] = []
    for i, f in enumerate(frames):
        p = f"{path}.keyframes[{i}]"
        fd = ck.table(f, p)
        ck.keys(fd, p, {"scan"} | _MIX_KEYS, {"background"})
        scan = ck.integer(fd["scan"], f"{p}.scan")
        if out and scan <= out[-1][0]:
            raise ValueError(
                f"{p}.scan: must be > the previous keyframe's scan ({scan} <= {out[-1][0]})"
            )
        ncomp = len(out[0][1].weights) if out else None
        if ncomp is not None:
            nw = len(_list(fd["weights"], f"{p}.weights"))
            if nw != ncomp:
                raise ValueError(
                    f"{p}.weights: expected {ncomp} components like keyframes[0], got {nw}"
                )
        out.append((scan, _mixture_from(fd, p, region, ncomp)))
    return TimeVaryingClutter(tuple(out))
