"""The true clutter intensity of one rotating radar at one time, per m² of the local plane
per rotation (a look) — what a clutter estimator of that radar should hold
(:mod:`mhtrack.clutter.per_sensor`) and what the clutter error is measured against.

For radar ``s`` at time ``t`` in its rotation ``n`` (middle ``τ_n``,
:func:`~mhtrack.scenario.sweep.rotation_middle`), at a plane point ``x`` at geodesic
range ``ρ(x)`` and at plane distance ``r`` and bearing ``θ`` from the site:

    κ_s(x, t) = 1[ρ(x) <= R_s] · ( κ_scene(x, τ_n) + N_u / (2π R_s r)
                + Σ_p N_p φ(r; r_p, σ_p) ψ(θ; θ_p, σ_θp) / r )

* ``κ_scene``: the scenario's :class:`~mhtrack.models.clutter_scene.ClutterScene` (its
  module docstring gives each component's formula);
* the radar's own clutter (:func:`~mhtrack.models.clutter.sample_range_azimuth`):
  ``N_u = clutter_rate`` uniform in range on ``[0, R_s]`` and in bearing — ``1/(2π R_s)``
  per unit range and radian, ``1/r`` the plane Jacobian — and each patch, normal in range
  (``φ``) and in bearing (``ψ``, the normal wrapped to the circle, in radians).

The radar's own clutter is drawn in its measured range and azimuth; the formula reads
them as the plane's polar coordinates about the site (exact at the frame's origin; the
azimuthal-equidistant frame distorts distances from another site by a relative
``O((d/6371 km)²)``, ``d`` its distance from the origin).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from mhtrack.models.clutter_scene import TWO_PI, polar_about
from mhtrack.models.sensors import RotatingRadar

#: Wraps of the bearing normal summed (``k = −2 … 2``): exact to ``1e−12`` for σ <= 90°.
_WRAPS = np.arange(-2, 3)


def _wrapped_normal(theta: np.ndarray, mean: float, sigma: float) -> np.ndarray:
    d = theta[:, None] - mean + TWO_PI * _WRAPS[None, :]
    return np.exp(-0.5 * (d / sigma) ** 2).sum(axis=1) / (math.sqrt(TWO_PI) * sigma)


def own_intensity(radar: RotatingRadar, xy: np.ndarray,
                  site: tuple[float, float]) -> np.ndarray:
    """The radar's own clutter (uniform range–azimuth and patches) per m² per rotation
    at plane points ``xy`` (module docstring; before ``max_range``)."""
    r, theta = polar_about(xy, site)
    rr = np.maximum(r, 1e-9)
    out = np.zeros(len(r))
    if radar.clutter_rate > 0 and radar.max_range is not None:
        out += np.where(r <= radar.max_range,
                        radar.clutter_rate / (TWO_PI * radar.max_range * rr), 0.0)
    for p in radar.clutter_patches:
        phi = np.exp(-0.5 * ((r - p.range) / p.sigma_range) ** 2) / (
            math.sqrt(TWO_PI) * p.sigma_range)
        psi = _wrapped_normal(theta, math.radians(p.bearing),
                              math.radians(p.sigma_bearing_deg))
        out += p.rate * phi * psi / rr
    return out


class RadarTruth:
    """``κ_s(x, t)`` of every radar of a rotating-radar ``scenario`` on fixed plane
    points ``xy`` (module docstring), with the parts that do not change over time (the
    coverage mask, the radar's own clutter) computed once per radar."""

    def __init__(self, scenario: Any, xy: np.ndarray) -> None:
        if not scenario.rotating:
            raise ValueError(f"scenario {scenario.name!r}: the true intensity per radar "
                             "needs rotating radars")
        self.scenario = scenario
        self.xy = np.asarray(xy, float).reshape(-1, 2)
        self.sensors = scenario.sensor_set()
        self.radars = {s.id: s for s in scenario.sensors}
        self._static: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def site(self, sensor_id: int) -> tuple[float, float]:
        return self.sensors.site_xy(sensor_id)

    def _fixed(self, sensor_id: int) -> tuple[np.ndarray, np.ndarray]:
        if sensor_id not in self._static:
            from mhtrack.models.geodesy import local_to_polar

            radar = self.radars[sensor_id]
            cover = np.ones(len(self.xy), bool)
            if radar.max_range is not None:
                rho, _ = local_to_polar(self.sensors.frame(),
                                        *self.sensors.site_latlon(sensor_id),
                                        self.xy[:, 0], self.xy[:, 1])
                cover = rho <= radar.max_range
            own = own_intensity(radar, self.xy, self.site(sensor_id))
            self._static[sensor_id] = (cover, np.where(cover, own, 0.0))
        return self._static[sensor_id]

    def rotation_time(self, sensor_id: int, t: float) -> float:
        """``τ_n``: the middle of the radar's rotation under way at ``t``."""
        from mhtrack.scenario.sweep import rotation_middle

        return float(rotation_middle(self.radars[sensor_id], t))

    def intensity(self, sensor_id: int, t: float) -> np.ndarray:
        """``κ_s(x, t)`` at the points (per m² per rotation)."""
        cover, own = self._fixed(int(sensor_id))
        scene = self.scenario.clutter_scene
        if scene is None:
            return own.copy()
        tau = self.rotation_time(int(sensor_id), t)
        return own + np.where(cover, scene.intensity(int(sensor_id), self.xy, tau,
                                                     self.site(int(sensor_id))), 0.0)
