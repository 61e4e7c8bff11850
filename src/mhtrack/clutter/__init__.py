"""Clutter intensity estimation: the ``κ̂(z)`` the tracker scores plots against."""

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.known import KnownClutter

__all__ = ["ClutterEstimator", "KnownClutter"]
