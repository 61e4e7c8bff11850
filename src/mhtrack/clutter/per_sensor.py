"""Clutter estimated per sensor: one estimator per radar, each fed only its own plots,
a full rotation at a time.

Each radar has its own clutter (ground returns around its site, its own false-alarm
rate), so one estimator over all radars' plots would give a plot of one radar the clutter
of another. :class:`PerSensorClutter` keeps one inner estimator (any
:class:`~mhtrack.clutter.base.ClutterEstimator`) per sensor id. Coordinates: the common
local east-north plane, in which every radar's clutter is stationary (the sites do not
move), unless ``wrap`` puts each inner estimator in its radar's own range and bearing
(:class:`~mhtrack.clutter.polar.PolarClutter`, the builder's default: measured in
docs/clutter.md).

*Per rotation.* A frame of a rotating radar holds one sector; ``κ`` in the score is the
clutter intensity per m² *per look* (P1 eqs. 5, 15), which for a rotating radar is per
rotation. The frames of a sensor are therefore gathered until they span its rotation
period and handed to its estimator as one scan; until a sensor's first rotation is
complete its intensity is ``initial`` (per m² per look). Plots the tracker gives to
confirmed tracks (:meth:`forget`) are left out of the gathered rotation. A sensor
without a period hands over every frame.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from mhtrack.bounds import MAX_INDEX, MAX_TIME_S
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.records import Scan


class PerSensorClutter(ClutterEstimator):
    """One estimator ``make()`` per sensor id (module docstring).

    Parameters
    ----------
    make : a fresh inner estimator (all of one kind).
    periods : rotation period (s) per sensor id (``None`` or absent: every frame is a
        scan of its own).
    initial : ``κ`` (per m² per look) of a sensor before its first full rotation.
    wrap : ``wrap(sensor_id, inner)`` turns a fresh inner estimator into the sensor's
        estimator (e.g. :class:`~mhtrack.clutter.polar.PolarClutter` about its site);
        default: the inner estimator itself.
    """

    name = "per-sensor"

    def __init__(self, make: Callable[[], ClutterEstimator],
                 periods: Mapping[int, float | None] | None = None, *,
                 initial: float = 1e-9,
                 wrap: Callable[[int, ClutterEstimator], ClutterEstimator] | None = None
                 ) -> None:
        self.make = make
        self.wrap = wrap
        self.periods = dict(periods or {})
        self.initial = float(initial)
        self._inner: dict[int, ClutterEstimator] = {}
        self._fed: set[int] = set()
        self._pending: dict[int, list[Scan]] = {}
        self._current: int | None = None
        self._start: dict[int, float] = {}  # first plot time of the gathered rotation

    def _sensor(self, scan: Scan) -> int:
        ids = np.unique(np.asarray(scan.sensor, np.int64))
        if ids.size > 1:
            raise ValueError(f"scan {scan.index}: PerSensorClutter needs one sensor per "
                             f"frame, got {ids.tolist()}")
        return int(ids[0]) if ids.size else (self._current or 0)

    def estimator(self, sensor_id: int) -> ClutterEstimator:
        """The inner estimator of ``sensor_id`` (made on first use)."""
        if sensor_id not in self._inner:
            inner = self.make()
            self._inner[sensor_id] = (inner if self.wrap is None
                                      else self.wrap(sensor_id, inner))
        return self._inner[sensor_id]

    def has_estimate(self, sensor_id: int) -> bool:
        """Whether ``sensor_id``'s estimator has been fed (its first rotation is complete)."""
        return sensor_id in self._fed

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        sid = self._current = self._sensor(scan)
        est = self.estimator(sid)
        pending = self._pending.setdefault(sid, [])
        period = self.periods.get(sid)
        if period is None:
            est.update(scan, in_track_gates)
            self._fed.add(sid)
            return
        if pending and float(scan.time) - self._start[sid] >= period:
            est.update(_merge(pending))
            self._fed.add(sid)
            pending.clear()
        if not pending:
            self._start[sid] = float(scan.plot_times().min()) if len(scan) else float(
                scan.time)
        pending.append(scan)

    def intensity(self, z: np.ndarray) -> np.ndarray:
        n = len(np.asarray(z).reshape(-1, 2))
        if self._current is None or self._current not in self._fed:
            return np.full(n, self.initial)
        return self._inner[self._current].intensity(z)

    def reference_intensity(self) -> float:
        """The current sensor's estimator's ``reference_intensity()`` (a clutter map's mean
        intensity, for the birth scaling), 0 before its first rotation or without one."""
        sid = self._current
        if sid is None or sid not in self._fed:
            return 0.0
        return float(self._inner[sid].reference_intensity())

    def forget(self, used: np.ndarray) -> None:
        sid = self._current
        if sid is None:
            return
        if self.periods.get(sid) is None:
            self.estimator(sid).forget(used)
            return
        pending = self._pending.get(sid)
        if not getattr(self.estimator(sid), "forget_used", True):
            return  # an estimator that keeps the tracks' plots (ClutterMap(forget_used=False))
        if pending and np.any(used):
            last = pending[-1]
            keep = ~np.asarray(used, bool)
            pending[-1] = Scan(last.index, last.time, last.z[keep], last.sensor[keep],
                               last.rows[keep], None if last.R is None else last.R[keep],
                               None, None if last.t is None else last.t[keep])

    def get_state(self) -> dict[str, Any]:
        ids = sorted(self._inner)
        return {
            "current": self._current, "fed": sorted(self._fed), "sensors": ids,
            "start": {str(i): v for i, v in self._start.items()},
            "inner": [self._inner[i].get_state() for i in ids],
            "pending": {str(i): [_scan_state(s) for s in self._pending.get(i, [])]
                        for i in ids},
        }

    def set_state(self, state: dict[str, Any]) -> None:
        from mhtrack.clutter.state_checks import check_scan, number

        f = "clutter_state"
        for i in [state["current"]] if state["current"] is not None else []:
            number(i, f"{f}.current", 0, MAX_INDEX, integer=True)
        for key in ("fed", "sensors"):
            if not isinstance(state[key], list):
                raise ValueError(f"field {f}.{key}: expected a list")
            for i in state[key]:
                number(i, f"{f}.{key}", 0, MAX_INDEX, integer=True)
        for v in state["start"].values():
            number(v, f"{f}.start", -MAX_TIME_S, MAX_TIME_S)
        for i in state["sensors"]:
            for j, s in enumerate(state["pending"][str(i)]):
                check_scan(s, f"{f}.pending[{i}][{j}]")
            if state["pending"][str(i)] and str(i) not in state["start"]:
                raise ValueError(f"field {f}.start: no time for sensor {i}'s pending frames")
        self._current = state["current"]
        self._fed = {int(i) for i in state["fed"]}
        self._start = {int(i): float(v) for i, v in state["start"].items()}
        self._inner, self._pending = {}, {}
        for i, inner in zip(state["sensors"], state["inner"], strict=True):
            self.estimator(int(i)).set_state(inner)
            self._pending[int(i)] = [_scan_of(s) for s in state["pending"][str(i)]]


def _merge(scans: list[Scan]) -> Scan:
    """One scan of a rotation's frames (positions, rows, sensor; time of the last)."""
    last = scans[-1]
    return Scan(last.index, last.time, np.concatenate([s.z for s in scans]).reshape(-1, 2),
                np.concatenate([s.sensor for s in scans]),
                np.concatenate([s.rows for s in scans]))


def _scan_state(s: Scan) -> dict[str, Any]:
    return {"index": int(s.index), "time": float(s.time), "z": np.asarray(s.z, float),
            "sensor": np.asarray(s.sensor, np.int64), "rows": np.asarray(s.rows, np.int64),
            "t": s.plot_times().astype(float)}


def _scan_of(d: dict[str, Any]) -> Scan:
    return Scan(int(d["index"]), float(d["time"]), np.asarray(d["z"], float).reshape(-1, 2),
                np.asarray(d["sensor"], np.int64), np.asarray(d["rows"], np.int64),
                t=np.asarray(d["t"], float))
