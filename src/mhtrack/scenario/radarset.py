"""A scenario's sensors as a :class:`~mhtrack.models.radars.SensorSet` — what a sensors
file holds (``docs/file-formats.md``) and what a tracker of real data is given.

* :class:`~mhtrack.models.sensors.RotatingRadar` → a polar ``RadarSensor`` with its site
  (``lat``/``lon`` or ``position``), ``σr``, ``σθ``, ``P_D``, ``period`` and ``max_range``
  (the beam's ``phase`` and the simulated clutter are not sensor-file keys);
* :class:`~mhtrack.models.sensors.PolarRadar` → a polar ``RadarSensor`` at its
  ``position`` (needs the scenario's ``origin`` to be put on the ellipsoid);
* :class:`~mhtrack.models.sensors.CartesianSensor` → a cartesian ``RadarSensor`` with σ.
"""

from __future__ import annotations

from collections.abc import Sequence

from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.models.sensors import CartesianSensor, PolarRadar, RotatingRadar, Sensor


def to_radar_sensor(s: Sensor, pd: float) -> RadarSensor:
    """One scenario sensor with its ``P_D`` as a :class:`RadarSensor`."""
    if isinstance(s, RotatingRadar):
        return RadarSensor(s.id, "polar", pd=pd, lat=s.lat, lon=s.lon, position=s.position,
                           sigma_range=s.sigma_range, sigma_bearing_deg=s.sigma_bearing_deg,
                           period=s.period, max_range=s.max_range)
    if isinstance(s, PolarRadar):
        return RadarSensor(s.id, "polar", pd=pd, position=s.position,
                           sigma_range=s.sigma_range, sigma_bearing_deg=s.sigma_bearing_deg)
    if isinstance(s, CartesianSensor):
        return RadarSensor(s.id, "cartesian", pd=pd, sigma=s.sigma)
    raise TypeError(f"sensor {s!r}: not a scenario sensor")


def to_sensor_set(
    origin: tuple[float, float] | None, sensors: Sequence[Sensor], pd: Sequence[float]
) -> SensorSet:
    """The :class:`SensorSet` of ``sensors`` (with their ``pd``) about ``origin`` (lat, lon;
    None: the first lat/lon site). Raises :class:`~mhtrack.models.radars.SensorFieldError`
    when a sensor does not fit a sensors file (e.g. ``P_D = 0``, or a polar sensor placed
    by position with no origin)."""
    return SensorSet(origin, tuple(to_radar_sensor(s, p)
                                   for s, p in zip(sensors, pd, strict=True)))
