"""The :class:`Scenario` record and its plain-dict (TOML) form, validated at the boundary.

A scenario is everything needed to simulate plots and truth: the surveillance region, the
scan period ``T`` and scan range, the targets, the sensors with their detection
probabilities, the clutter model and the truth process noise. Scan ``k`` is at time
``t = k·T`` (s).

Clutter is applied **per sensor**: at every scan each sensor draws its own Poisson number
of clutter plots (mean ``λ_k``) from the same clutter model, independently of the others,
so with ``S`` sensors a scan holds on average ``S·λ_k`` clutter plots.

The dict form (what :meth:`Scenario.to_dict` writes and :func:`from_dict` reads; see
``docs/scenarios.md``) is made of tables, lists, strings and numbers only, so it can be
written to TOML as is. :func:`from_dict` rejects unknown keys, wrong types and non-finite
numbers with a ``ValueError`` naming the key path, e.g. ``targets[2].birth: must be <=
death (50 > 40)``.
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.errors import InputError
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
    Sensor,
)
from mhtrack.records import MAX_COORDINATE
from mhtrack.scenario import _check as ck
from mhtrack.scenario.targets import AnyTarget, RecordedTarget, Target

ClutterSpec = UniformClutter | GaussianMixtureClutter | TimeVaryingClutter

#: Clutter kinds of the dict form.
CLUTTER_KINDS = ("uniform", "gmm", "time-varying")
#: Sensor kinds of the dict form.
SENSOR_KINDS = ("cartesian", "polar")

# ---------------------------------------------------------------------- limits
# Bounds beyond which a scenario is refused up front, before any memory is allocated or a
# number overflows (see docs/scenarios.md, "Limits"). Sensor limits: ``MAX_SIGMA`` (m),
# ``MAX_SIGMA_BEARING_DEG`` in :mod:`mhtrack.models.sensors`; ``MAX_COORDINATE`` in
# :mod:`mhtrack.records`.

#: Largest number of scans of a scenario (``last − first + 1``).
MAX_SCANS = 100_000
#: Largest expected number of plots of one simulation: sensors × mean clutter rate × scans
#: plus the target plots (each plot costs about 100 bytes in the tables).
MAX_PLOTS = 50_000_000
#: Largest scan period ``T`` (s): about 11.6 days.
MAX_T = 1e6
#: Largest ``|velocity component|`` of a target (m/s): 100 km/s.
MAX_SPEED = 1e5
#: Largest truth acceleration noise ``truth_sigma_v`` (m/s²): about 1000 g.
MAX_SIGMA_V = 1e4


@dataclass(frozen=True, eq=False, kw_only=True)
class Scenario:
    """A simulation scenario (all lengths in m, times in s).

    Attributes
    ----------
    name : label of the scenario.
    region : surveillance region; the clutter model must use the same region.
    T : scan period; scan ``k`` is at time ``k·T``.
    scans : ``(first, last)`` scan indices, inclusive, ``0 <= first <= last``.
    targets : :class:`Target` / :class:`RecordedTarget`, unique ids ``>= 0``. Targets may
        live partly (or wholly) outside ``scans``; only scans in range are simulated.
    sensors : :class:`CartesianSensor` / :class:`PolarRadar`, unique ids ``>= 0``.
    pd : detection probability of each sensor (a single number is broadcast).
    clutter : uniform, Gaussian-mixture or time-varying clutter model, drawn per sensor.
    truth_sigma_v : acceleration noise σv (m/s²) on the truth of :class:`Target` s
        (``Q(T)·σv²``, P1 §1.1); 0 = exact straight lines (default).
    description : free text (where the parameters come from).

    Two scenarios compare equal when their dict forms are equal, numbers to 1e-12
    relative (mixture weights are renormalised on construction).
    """

    name: str
    region: Region
    T: float
    scans: tuple[int, int]
    sensors: tuple[Sensor, ...]
    pd: tuple[float, ...] | float
    clutter: ClutterSpec
    targets: tuple[AnyTarget, ...] = ()
    truth_sigma_v: float = 0.0
    description: str = field(default="")

    def __post_init__(self) -> None:
        ck.string(self.name, "name")
        ck.string(self.description, "description")
        if not isinstance(self.region, Region):
            raise ValueError(f"region: expected a Region, got {type(self.region).__name__}")
        _check_region(self.region, "region")
        object.__setattr__(self, "T", _period(self.T))
        object.__setattr__(self, "truth_sigma_v", _sigma_v(self.truth_sigma_v))
        sc = tuple(self.scans)
        if len(sc) != 2:
            raise ValueError(f"scans: expected [first, last], got {self.scans!r}")
        object.__setattr__(self, "scans", _scan_range(sc[0], sc[1]))

        sensors = tuple(self.sensors)
        if not sensors:
            raise ValueError("sensors: at least one sensor is needed")
        seen: set[int] = set()
        for i, s in enumerate(sensors):
            if not isinstance(s, CartesianSensor | PolarRadar):
                raise ValueError(f"sensors[{i}]: expected a CartesianSensor or PolarRadar")
            sid = ck.integer(s.id, f"sensors[{i}].id", lo=0)
            if sid in seen:
                raise ValueError(f"sensors[{i}].id: duplicate id {sid}")
            seen.add(sid)
        object.__setattr__(self, "sensors", sensors)
        pd = self.pd
        if isinstance(pd, int | float | np.integer | np.floating) and not isinstance(pd, bool):
            pd = (pd,) * len(sensors)
        pd = tuple(pd)  # type: ignore[arg-type]
        if len(pd) != len(sensors):
            raise ValueError(f"pd: expected one per sensor ({len(sensors)}), got {len(pd)}")
        pd = tuple(ck.probability(p, f"sensors[{i}].pd") for i, p in enumerate(pd))
        object.__setattr__(self, "pd", pd)

        if not isinstance(
            self.clutter, UniformClutter | GaussianMixtureClutter | TimeVaryingClutter
        ):
            raise ValueError(
                f"clutter: expected a uniform, Gaussian-mixture or time-varying clutter "
                f"model, got {type(self.clutter).__name__}"
            )
        if self.clutter.region != self.region:
            raise ValueError(
                f"clutter: region {self.clutter.region.as_tuple()} differs from the "
                f"scenario region {self.region.as_tuple()}"
            )

        targets = tuple(self.targets)
        tids: set[int] = set()
        for i, t in enumerate(targets):
            if not isinstance(t, Target | RecordedTarget):
                raise ValueError(f"targets[{i}]: expected a Target or RecordedTarget")
            if t.id in tids:
                raise ValueError(f"targets[{i}].id: duplicate id {t.id}")
            tids.add(t.id)
            if isinstance(t, Target):
                _check_state(t.state, f"targets[{i}].state")
            else:
                for j, row in enumerate(t.states):
                    _check_state(row, f"targets[{i}].states[{j}]")
        object.__setattr__(self, "targets", targets)
        self._check_size()

    def _check_size(self) -> None:
        """Refuse a scenario whose simulation would not fit in memory (:data:`MAX_PLOTS`)
        or whose truth noise would be drawn over more than :data:`MAX_SCANS` steps."""
        first, last = self.scans
        n_sensors = len(self.sensors)
        target_scans = 0
        for i, t in enumerate(self.targets):
            if isinstance(t, Target):
                target_scans += max(0, min(t.death, last) - max(t.birth, first) + 1)
                steps = min(t.death, last) - t.birth
                if self.truth_sigma_v > 0 and steps > MAX_SCANS and t.death >= first:
                    raise ValueError(
                        f"targets[{i}].birth: with truth_sigma_v > 0 the truth noise is drawn "
                        f"from the birth scan {t.birth} on, {steps} steps, more than "
                        f"{MAX_SCANS} (MAX_SCANS)"
                    )
            else:
                target_scans += sum(first <= k <= last for k in t.scans)
        clutter = n_sensors * self.mean_clutter_rate() * self.n_scans
        total = clutter + n_sensors * target_scans
        if total <= MAX_PLOTS:
            return
        c = self.clutter
        if clutter < n_sensors * target_scans:
            key = "targets"
        elif isinstance(c, TimeVaryingClutter):
            i = int(np.argmax([m.rate_per_scan for _, m in c.keyframes]))
            key = f"clutter.keyframes[{i}].rate"
        else:
            key = "clutter.rate"
        raise ValueError(
            f"{key}: a simulation would give about {ck.fmt(float(f'{total:.3g}'))} plots "
            f"({n_sensors} sensor(s) × mean clutter rate {ck.fmt(self.mean_clutter_rate())} "
            f"× {self.n_scans} scans + {n_sensors * target_scans} target plots), more than "
            f"the maximum {ck.fmt(MAX_PLOTS)} (MAX_PLOTS); lower the clutter rate or the "
            f"number of scans"
        )

    # ------------------------------------------------------------------ derived values
    @property
    def first(self) -> int:
        return self.scans[0]

    @property
    def last(self) -> int:
        return self.scans[1]

    @property
    def n_scans(self) -> int:
        return self.scans[1] - self.scans[0] + 1

    def scan_indices(self) -> np.ndarray:
        """All scan indices ``first..last``."""
        return np.arange(self.first, self.last + 1, dtype=np.int64)

    def scan_times(self) -> np.ndarray:
        """Time of every scan, ``t_k = k·T`` (s)."""
        return self.scan_indices() * self.T

    def clutter_rate(self, scan: int) -> float:
        """Mean clutter count per sensor at ``scan`` (``λ_k``)."""
        return float(self.clutter.rate(scan))

    def mean_clutter_rate(self) -> float:
        """Mean of ``λ_k`` over the scans of the range (per sensor)."""
        c = self.clutter
        if isinstance(c, TimeVaryingClutter):
            ks = np.array([k for k, _ in c.keyframes], float)
            rates = np.array([m.rate_per_scan for _, m in c.keyframes], float)
            # linear between keyframes, constant outside: exactly np.interp
            return float(np.interp(self.scan_indices().astype(float), ks, rates).mean())
        return float(c.rate_per_scan)

    def mean_clutter_density(self) -> float:
        """``S λ̄ / A``: the mean clutter count per scan of all ``S`` sensors spread
        uniformly over the region (plots per m² per scan)."""
        return len(self.sensors) * self.mean_clutter_rate() / self.region.area

    # ------------------------------------------------------------------ dict form
    def to_dict(self) -> dict[str, Any]:
        """Plain nested dict (tables, lists, strings, numbers) — the TOML schema of
        ``docs/scenarios.md``; :func:`from_dict` reads it back to an equal scenario."""
        return {
            "name": self.name,
            "description": self.description,
            "T": float(self.T),
            "scans": [self.first, self.last],
            "truth_sigma_v": float(self.truth_sigma_v),
            "region": _region_to_dict(self.region),
            "sensors": [_sensor_to_dict(s, p) for s, p in zip(self.sensors, self.pd, strict=True)],
            "targets": [_target_to_dict(t) for t in self.targets],
            "clutter": clutter_to_dict(self.clutter),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Scenario:
        """Validated inverse of :meth:`to_dict` (see :func:`from_dict`)."""
        return from_dict(d)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Scenario):
            return NotImplemented
        return ck.close(self.to_dict(), other.to_dict())

    __hash__ = None  # type: ignore[assignment]


# ---------------------------------------------------------------------- to dict
def _region_to_dict(r: Region) -> dict[str, float]:
    return {
        "xmin": float(r.xmin),
        "xmax": float(r.xmax),
        "ymin": float(r.ymin),
        "ymax": float(r.ymax),
    }


def _sensor_to_dict(s: Sensor, pd: float) -> dict[str, Any]:
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


def _target_to_dict(t: AnyTarget) -> dict[str, Any]:
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
_TOP_REQUIRED = {"T", "scans", "region", "sensors", "clutter"}
_TOP_OPTIONAL = {"name", "description", "targets", "truth_sigma_v", "seed"}


def from_dict(d: Mapping[str, Any]) -> Scenario:
    """Build a :class:`Scenario` from its dict form, validating every key.

    Target ``birth`` / ``death`` may be left out: they default to the first / last scan.
    An optional top-level ``seed`` (integer ``>= 0``, what the CLI records next to the
    parameters in ``scenario.toml``) is validated and otherwise ignored: a seed belongs to
    a simulation, not to a scenario.
    Raises ``ValueError`` whose message starts with the offending key path.
    """
    d = ck.table(d, "")
    ck.keys(d, "", _TOP_REQUIRED, _TOP_OPTIONAL)
    if "seed" in d:
        ck.integer(d["seed"], "seed", lo=0)
    name = ck.string(d.get("name", "custom"), "name")
    description = ck.string(d.get("description", ""), "description")
    T = _period(d["T"])
    sigma_v = _sigma_v(d.get("truth_sigma_v", 0.0))
    scans = d["scans"]
    if not isinstance(scans, list | tuple) or len(scans) != 2:
        raise ValueError(f"scans: expected [first, last], got {scans!r}")
    first, last = _scan_range(scans[0], scans[1])
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
    clutter = _clutter_from(d["clutter"], "clutter", region)
    return Scenario(
        name=name,
        description=description,
        region=region,
        T=T,
        scans=(first, last),
        sensors=tuple(sensors),
        pd=tuple(pds),
        clutter=clutter,
        targets=tuple(targets),
        truth_sigma_v=sigma_v,
    )


def load_scenario(source: str | os.PathLike[str] | Mapping[str, Any]) -> Scenario:
    """A scenario from a TOML file (path) or from its dict form (see :func:`from_dict`).

    The file is UTF-8, with or without a byte-order mark. Errors name the file:
    ``<file>: not valid UTF-8 text (byte 0xe9 on line 6)``, ``<file>: not valid TOML: …``,
    ``<file>: <key path>: …``.
    """
    if isinstance(source, Mapping):
        return from_dict(source)
    path = Path(source)
    try:
        raw = path.read_bytes()
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror or e})", file=str(path)) from None
    try:
        text = raw.decode("utf-8-sig")  # a UTF-8 byte-order mark is accepted and dropped
    except UnicodeDecodeError as e:
        line = raw.count(b"\n", 0, e.start) + 1
        raise InputError(
            f"{path}: not valid UTF-8 text (byte 0x{raw[e.start]:02x} on line {line})",
            file=str(path),
            line=line,
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"{path}: not valid TOML: {e}") from None
    try:
        return from_dict(data)
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None


def _period(v: object) -> float:
    return ck.number(v, "T", lo=0.0, lo_open=True, hi=MAX_T, unit="s")


def _sigma_v(v: object) -> float:
    return ck.number(v, "truth_sigma_v", lo=0.0, hi=MAX_SIGMA_V, unit="m/s²")


def _scan_range(first: object, last: object) -> tuple[int, int]:
    """Validated ``(first, last)``; at most :data:`MAX_SCANS` scans."""
    f = ck.integer(first, "scans[0]", lo=0)
    la = ck.integer(last, "scans[1]", lo=0)
    if f > la:
        raise ValueError(f"scans: first must be <= last, got [{f}, {la}]")
    if la - f + 1 > MAX_SCANS:
        raise ValueError(
            f"scans: [{f}, {la}] is {la - f + 1} scans, more than the maximum {MAX_SCANS} "
            f"(MAX_SCANS)"
        )
    if la > _MAX_SCAN_INDEX:
        raise ValueError(f"scans[1]: must be <= {_MAX_SCAN_INDEX} (2**53), got {la}")
    return f, la


#: Largest scan index: scan times ``k·T`` and int64 scan arrays stay exact.
_MAX_SCAN_INDEX = 2**53


def _check_region(r: Region, path: str) -> None:
    for k in ("xmin", "xmax", "ymin", "ymax"):
        ck.bounded(getattr(r, k), ck.join(path, k), MAX_COORDINATE)


def _check_state(state: Any, path: str) -> None:
    """``[x, vx, y, vy]`` within ±:data:`MAX_COORDINATE` m and ±:data:`MAX_SPEED` m/s."""
    for j, v in enumerate(state):
        if j % 2 == 0:
            ck.bounded(v, f"{path}[{j}]", MAX_COORDINATE)
        else:
            ck.bounded(v, f"{path}[{j}]", MAX_SPEED, "m/s")


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
    return sensor, ck.probability(d["pd"], f"{path}.pd")


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
        st = ck.array(d["states"], f"{path}.states", (len(sc), 4))
        for i, row in enumerate(st):
            _check_state(row, f"{path}.states[{i}]")
        with ck.at(path):
            return RecordedTarget(tid, tuple(sc), tuple(map(tuple, st.tolist())))
    ck.keys(d, path, {"id", "state"}, {"birth", "death"})
    tid = ck.integer(d["id"], f"{path}.id", lo=0)
    state = ck.array(d["state"], f"{path}.state", (4,))
    _check_state(state, f"{path}.state")
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
