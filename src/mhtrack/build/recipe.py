"""A tracker's radars as JSON-able values, saved with its state (the builder's recipe,
:func:`mhtrack.build.load_tracker`)."""

from __future__ import annotations

import dataclasses
from typing import Any

from mhtrack.models.radars import RadarSensor, SensorSet


def sensors_recipe(sensors: SensorSet) -> dict[str, Any]:
    """``sensors`` as JSON-able values (:func:`sensors_from_recipe` reverses it)."""
    return {"origin": None if sensors.origin is None else list(sensors.origin),
            "sensors": [{k: (list(v) if isinstance(v, tuple) else v)
                         for k, v in dataclasses.asdict(s).items()}
                        for s in sensors.sensors]}


def sensors_from_recipe(d: dict[str, Any]) -> SensorSet:
    """The :class:`SensorSet` of :func:`sensors_recipe`."""
    return SensorSet(None if d["origin"] is None else tuple(d["origin"]), tuple(
        RadarSensor(**{k: (tuple(v) if isinstance(v, list) else v) for k, v in s.items()})
        for s in d["sensors"]))


