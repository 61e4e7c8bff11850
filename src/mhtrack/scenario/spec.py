"""The :class:`Scenario` record and its plain-dict (TOML) form, validated at the boundary.

A scenario is everything needed to simulate plots and truth: the surveillance region, the
scan period ``T`` and scan range, the targets, the sensors with their detection
probabilities, the clutter model and the truth process noise. Scan ``k`` is at time
``t = k·T`` (s).

Clutter is applied **per sensor**: at every scan each sensor draws its own Poisson number
of clutter plots (mean ``λ_k``) from the same clutter model, independently of the others,
so with ``S`` sensors a scan holds on average ``S·λ_k`` clutter plots.

The dict form (what :meth:`Scenario.to_dict` writes and :func:`from_dict` reads; see
``docs/scenarios.md`` and :mod:`mhtrack.scenario.dictform`) can be written to TOML as is;
:func:`load_scenario` reads a TOML file with the one TOML reader
(:func:`mhtrack.io.read_toml`). Errors name the key path, e.g. ``targets[2].birth: must
be <= death (50 > 40)``, and, from a file, the file first. Bounds:
:mod:`mhtrack.scenario.limits`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from mhtrack.io.tomlfile import key_error, read_toml
from mhtrack.models.clutter import (
    GaussianMixtureClutter,
    Region,
    TimeVaryingClutter,
    UniformClutter,
)
from mhtrack.models.clutter_scene import ClutterScene
from mhtrack.models.sensors import CartesianSensor, PolarRadar, RotatingRadar, Sensor
from mhtrack.scenario import _check as ck
from mhtrack.scenario.dictform import (
    ClutterSpec,
    clutter_to_dict,
    region_to_dict,
    scenario_fields,
    sensor_to_dict,
    target_to_dict,
)
from mhtrack.scenario.limits import (
    MAX_PLOTS,
    MAX_SCANS,
    MAX_T,
    check_period,
    check_region,
    check_scan_range,
    check_sigma_v,
    check_state,
)
from mhtrack.scenario.targets import AnyTarget, RecordedTarget, Target

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet


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
    origin : ``(lat, lon)`` WGS-84 degrees of the local frame's tangent point, or None
        (then the first sensor with ``lat``/``lon``): the geodetic frame of
        :meth:`sensor_set` and of rotating radars.
    truth_dt : with rotating radars, the truth is sampled every ``truth_dt`` s (default 1).
    clutter_scene : with rotating radars, a changing clutter scene each radar draws per
        rotation on top of its own clutter (:mod:`mhtrack.models.clutter_scene`), or None.
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
    origin: tuple[float, float] | None = None
    truth_dt: float = 1.0
    clutter_scene: ClutterScene | None = None

    def __post_init__(self) -> None:
        ck.string(self.name, "name")
        ck.string(self.description, "description")
        if not isinstance(self.region, Region):
            raise ValueError(f"region: expected a Region, got {type(self.region).__name__}")
        check_region(self.region, "region")
        object.__setattr__(self, "T", check_period(self.T))
        object.__setattr__(self, "truth_sigma_v", check_sigma_v(self.truth_sigma_v))
        sc = tuple(self.scans)
        if len(sc) != 2:
            raise ValueError(f"scans: expected [first, last], got {self.scans!r}")
        object.__setattr__(self, "scans", check_scan_range(sc[0], sc[1]))

        sensors = tuple(self.sensors)
        if not sensors:
            raise ValueError("sensors: at least one sensor is needed")
        seen: set[int] = set()
        for i, s in enumerate(sensors):
            if not isinstance(s, CartesianSensor | PolarRadar | RotatingRadar):
                raise ValueError(f"sensors[{i}]: expected a CartesianSensor, PolarRadar or "
                                 "RotatingRadar")
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
        pd = tuple(ck.detection_probability(p, f"sensors[{i}].pd") for i, p in enumerate(pd))
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

        self._check_rotating()

        targets = tuple(self.targets)
        tids: set[int] = set()
        for i, t in enumerate(targets):
            if not isinstance(t, Target | RecordedTarget):
                raise ValueError(f"targets[{i}]: expected a Target or RecordedTarget")
            if t.id in tids:
                raise ValueError(f"targets[{i}].id: duplicate id {t.id}")
            tids.add(t.id)
            if isinstance(t, Target):
                check_state(t.state, f"targets[{i}].state")
            else:
                for j, row in enumerate(t.states):
                    check_state(row, f"targets[{i}].states[{j}]")
        object.__setattr__(self, "targets", targets)
        self._check_size()

    def _check_rotating(self) -> None:
        """Rotating radars: all sensors rotate, the region clutter is off (they draw their
        own), and there is a geodetic origin (``origin`` or a radar's ``lat``/``lon``)."""
        if self.origin is not None:
            o = tuple(self.origin)
            if len(o) != 2:
                raise ValueError(f"origin: expected (lat, lon), got {self.origin!r}")
            lat = ck.number(o[0], "origin.lat", lo=-90.0, hi=90.0, unit="degrees")
            lon = ck.number(o[1], "origin.lon", lo=-180.0, hi=180.0, unit="degrees")
            object.__setattr__(self, "origin", (lat, lon))
        object.__setattr__(self, "truth_dt", ck.number(
            self.truth_dt, "truth_dt", lo=0.0, lo_open=True, hi=MAX_T, unit="s"))
        if not self.rotating:
            if self.clutter_scene is not None:
                raise ValueError("clutter_scene: drawn by rotating radars only (give the "
                                 "sensors a period)")
            return
        if self.clutter_scene is not None and not isinstance(self.clutter_scene, ClutterScene):
            raise ValueError("clutter_scene: expected a ClutterScene")
        for i, s in enumerate(self.sensors):
            if not isinstance(s, RotatingRadar):
                raise ValueError(
                    f"sensors[{i}]: a {s.kind} sensor without a period cannot be mixed with "
                    "rotating radars (give every sensor a period, or none)")
        if self.mean_clutter_rate() > 0:
            raise ValueError(
                "clutter.rate: rotating radars draw their own clutter per rotation "
                "(sensors[].clutter_rate, sensors[].clutter_patches); the region's "
                "clutter model must have rate 0")
        if self.origin is None and all(s.lat is None for s in self.sensors):  # type: ignore[union-attr]
            raise ValueError("origin: rotating radars are placed on the WGS-84 ellipsoid: "
                             "give origin = {lat, lon} or a radar's lat/lon")
        n_steps = (self.last - self.first) * self.T / self.truth_dt
        if n_steps > MAX_SCANS:
            raise ValueError(f"truth_dt: {n_steps:.3g} truth samples, more than "
                             f"{MAX_SCANS} (MAX_SCANS)")

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
        looks = float(n_sensors)  # plots per target and scan
        if self.rotating:  # one look and one clutter draw per rotation
            turns = [self.T / s.period for s in self.sensors]  # type: ignore[union-attr]
            looks = sum(turns)
            clutter = self.n_scans * sum(
                n * (s.mean_clutter() + self._scene_rate(s.id))  # type: ignore[union-attr]
                for n, s in zip(turns, self.sensors, strict=True))
        total = clutter + looks * target_scans
        if total <= MAX_PLOTS:
            return
        c = self.clutter
        if clutter < looks * target_scans:
            key = "targets"
        elif self.rotating:
            key = "sensors[].clutter_rate"
        elif isinstance(c, TimeVaryingClutter):
            i = int(np.argmax([m.rate_per_scan for _, m in c.keyframes]))
            key = f"clutter.keyframes[{i}].rate"
        else:
            key = "clutter.rate"
        raise ValueError(
            f"{key}: a simulation would give about {ck.fmt(float(f'{total:.3g}'))} plots "
            f"({n_sensors} sensor(s) × mean clutter rate {ck.fmt(self.mean_clutter_rate())} "
            f"× {self.n_scans} scans + {ck.fmt(looks * target_scans)} target plots), more than "
            f"the maximum {ck.fmt(MAX_PLOTS)} (MAX_PLOTS); lower the clutter rate or the "
            f"number of scans"
        )

    def _scene_rate(self, sensor_id: int) -> float:
        """Mean scene clutter per rotation of a radar over the run (0 without a scene)."""
        sc = self.clutter_scene
        return 0.0 if sc is None else sc.mean_rate(sensor_id, self.first * self.T,
                                                   self.last * self.T)

    # ------------------------------------------------------------------ derived values
    @property
    def rotating(self) -> bool:
        """The sensors are rotating radars (plots timed by the beam, ``docs/scenarios.md``)."""
        return any(isinstance(s, RotatingRadar) for s in self.sensors)

    def sensor_set(self) -> SensorSet:
        """The sensors as :class:`~mhtrack.models.radars.SensorSet` (what a sensors file
        holds) with this scenario's ``origin``; see
        :func:`mhtrack.scenario.radarset.to_sensor_set`."""
        from mhtrack.scenario.radarset import to_sensor_set

        return to_sensor_set(self.origin, self.sensors, self.pd)  # type: ignore[arg-type]

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
        ``docs/scenarios.md``; :func:`from_dict` reads it back to an equal scenario.
        ``origin`` is written when set and ``truth_dt`` for rotating radars only."""
        extra: dict[str, Any] = {}
        if self.origin is not None:
            extra["origin"] = {"lat": self.origin[0], "lon": self.origin[1]}
        if self.rotating:
            extra["truth_dt"] = float(self.truth_dt)
        if self.clutter_scene is not None:
            from mhtrack.scenario.scenedict import scene_to_dict

            extra["clutter_scene"] = scene_to_dict(self.clutter_scene)
        return {
            "name": self.name,
            "description": self.description,
            "T": float(self.T),
            "scans": [self.first, self.last],
            "truth_sigma_v": float(self.truth_sigma_v),
            "region": region_to_dict(self.region),
            "sensors": [sensor_to_dict(s, p) for s, p in zip(self.sensors, self.pd, strict=True)],
            "targets": [target_to_dict(t) for t in self.targets],
            "clutter": clutter_to_dict(self.clutter),
            **extra,
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


def from_dict(d: Mapping[str, Any]) -> Scenario:
    """Build a :class:`Scenario` from its dict form, validating every key
    (:func:`~mhtrack.scenario.dictform.scenario_fields`).

    Target ``birth`` / ``death`` may be left out: they default to the first / last scan.
    An optional top-level ``seed`` is validated and otherwise ignored. Raises
    ``ValueError`` whose message starts with the offending key path.
    """
    return Scenario(**scenario_fields(d))


def load_scenario(source: str | os.PathLike[str] | Mapping[str, Any]) -> Scenario:
    """A scenario from a TOML file (path) or from its dict form (see :func:`from_dict`).

    The file is read by :func:`mhtrack.io.read_toml` (UTF-8, with or without a byte-order
    mark). Every error is an :class:`~mhtrack.errors.InputError` naming the file, then the
    line or the key path: ``<file>, line 6: not valid UTF-8 text (byte 0xe9)``,
    ``<file>, line 1, column 5: <TOML syntax error>``, ``<file>: T: must be > 0 …``.
    """
    if isinstance(source, Mapping):
        return from_dict(source)
    data = read_toml(source)
    try:
        return from_dict(data)
    except ValueError as e:
        raise key_error(source, e) from None
