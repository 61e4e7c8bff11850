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
    """``κ_s(x, t)`` of every radar of a rotating-radar ``scenario`` (module docstring):
    at fixed plane points ``xy`` (a grid), with the parts that do not change over time
    (coverage, the radar's own clutter) computed once per radar, or at any points."""

    def __init__(self, scenario: Any, xy: np.ndarray | None = None) -> None:
        if not scenario.rotating:
            raise ValueError(f"scenario {scenario.name!r}: the true intensity per radar "
                             "needs rotating radars")
        self.scenario = scenario
        self.xy = np.zeros((0, 2)) if xy is None else np.asarray(xy, float).reshape(-1, 2)
        self.sensors = scenario.sensor_set()
        self.radars = {s.id: s for s in scenario.sensors}
        self._static: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        #: The last points asked for per radar, with their parts (the same points again
        #: are not recomputed: a grid probed after every frame).
        self._last: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def site(self, sensor_id: int) -> tuple[float, float]:
        return self.sensors.site_xy(sensor_id)

    def _parts(self, sensor_id: int, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Coverage mask and the radar's own clutter at ``xy``."""
        from mhtrack.models.geodesy import local_to_polar

        radar = self.radars[sensor_id]
        cover = np.ones(len(xy), bool)
        if radar.max_range is not None:
            rho, _ = local_to_polar(self.sensors.frame(), *self.sensors.site_latlon(sensor_id),
                                    xy[:, 0], xy[:, 1])
            cover = rho <= radar.max_range
        return cover, np.where(cover, own_intensity(radar, xy, self.site(sensor_id)), 0.0)

    def _fixed(self, sensor_id: int) -> tuple[np.ndarray, np.ndarray]:
        if sensor_id not in self._static:
            self._static[sensor_id] = self._parts(sensor_id, self.xy)
        return self._static[sensor_id]

    def coverage(self, sensor_id: int) -> np.ndarray:
        """The fixed points within the radar's ``max_range`` (geodesic)."""
        return self._fixed(int(sensor_id))[0]

    def rotation_time(self, sensor_id: int, t: float) -> float:
        """``τ_n``: the middle of the radar's rotation under way at ``t``."""
        from mhtrack.scenario.sweep import rotation_middle

        return float(rotation_middle(self.radars[sensor_id], t))

    def intensity(self, sensor_id: int, t: float, xy: np.ndarray | None = None) -> np.ndarray:
        """``κ_s(x, t)`` (per m² per rotation) at the fixed points, or at ``xy``."""
        sid = int(sensor_id)
        if xy is None:
            pts, (cover, own) = self.xy, self._fixed(sid)
        else:
            pts = np.asarray(xy, float).reshape(-1, 2)
            last = self._last.get(sid)
            if last is None or last[0].shape != pts.shape or not np.array_equal(last[0], pts):
                last = self._last[sid] = (pts.copy(), *self._parts(sid, pts))
            cover, own = last[1], last[2]
        scene = self.scenario.clutter_scene
        if scene is None:
            return own.copy()
        tau = self.rotation_time(sid, t)
        return own + np.where(cover, scene.intensity(sid, pts, tau, self.site(sid)), 0.0)
