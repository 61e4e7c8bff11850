"""Models and filters: motion, sensors, batched Kalman filtering, clutter densities."""

from mhtrack.models.motion import ConstantVelocity, H
from mhtrack.models.sensors import CartesianSensor, Observation, PolarRadar, Sensor

__all__ = ["CartesianSensor", "ConstantVelocity", "H", "Observation", "PolarRadar", "Sensor"]
