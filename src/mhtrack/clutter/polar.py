"""Clutter estimated in a radar's own range and bearing.

A rotating radar's clutter is often stationary and simple in its own polar coordinates
— thermal false alarms uniform in range and azimuth, sea or ground clutter in a band of
ranges over a sector — and curved or singular in the east-north plane (uniform in
range–azimuth is ``∝ 1/r`` in the plane). :class:`PolarClutter` wraps any estimator
and hands it each plot as ``(r, r₀·θ)``: ``r`` the plane distance from the site, ``θ``
the grid bearing (radians, clockwise from grid north, cut at ``θ_cut``) and ``r₀`` a
reference range that gives both axes metres, so that a Gaussian mixture sees comparable
scales. The change of variables ``dA = r dr dθ = (r / r₀) dr d(r₀θ)`` turns the inner
intensity into one per m² of the plane:

    κ(x, y) = κ_polar(r, r₀θ) · r₀ / r

(the Jacobian of plane polar coordinates, e.g. any calculus text). Ranges below
``min_range`` are held at ``min_range`` in the Jacobian so that κ stays finite at the
site. Bearing is cut at ``θ_cut`` (default: due south, where most radars of a network
look least); a clutter patch across the cut is seen as two.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.records import Scan


class PolarClutter(ClutterEstimator):
    """``inner`` fed ``(r, r₀θ)`` about ``site`` (module docstring).

    Parameters
    ----------
    inner : the estimator in polar coordinates (any :class:`ClutterEstimator`).
    site : the radar's site (x, y) in the local frame (m).
    r0 : reference range (m) scaling the bearing axis (default 100 km).
    min_range : floor of ``r`` in the Jacobian (m).
    cut_deg : grid bearing (degrees) where the bearing axis starts and ends.
    """

    name = "polar"

    def __init__(self, inner: ClutterEstimator, site: tuple[float, float], *,
                 r0: float = 100_000.0, min_range: float = 1_000.0,
                 cut_deg: float = 180.0) -> None:
        if not (r0 > 0 and min_range > 0):
            raise ValueError(f"r0 and min_range must be > 0, got {r0:g}, {min_range:g}")
        self.inner = inner
        self.site = (float(site[0]), float(site[1]))
        self.r0 = float(r0)
        self.min_range = float(min_range)
        self.cut = np.radians(float(cut_deg))

    def to_polar(self, z: np.ndarray) -> np.ndarray:
        """``(r, r₀θ)`` of plane positions ``z`` (n, 2); θ ∈ [0, 2π) from the cut."""
        z = np.asarray(z, float).reshape(-1, 2)
        dx, dy = z[:, 0] - self.site[0], z[:, 1] - self.site[1]
        theta = np.mod(np.arctan2(dx, dy) - self.cut, 2.0 * np.pi)
        return np.column_stack([np.hypot(dx, dy), self.r0 * theta])

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        self.inner.update(Scan(scan.index, scan.time, self.to_polar(scan.z), scan.sensor,
                               scan.rows, None, None, scan.t), in_track_gates)

    def intensity(self, z: np.ndarray) -> np.ndarray:
        p = self.to_polar(z)
        return self.inner.intensity(p) * self.r0 / np.maximum(p[:, 0], self.min_range)

    def forget(self, used: np.ndarray) -> None:
        self.inner.forget(used)

    def reference_intensity(self) -> float:
        """The inner estimator's mean level, per m² of its own (polar) plane: ``0`` unless
        the inner estimator has one (a clutter map is never wrapped; the builder places it
        about the site in the plane)."""
        return self.inner.reference_intensity()

    def get_state(self) -> dict[str, Any]:
        return {"inner": self.inner.get_state()}

    def set_state(self, state: dict[str, Any]) -> None:
        self.inner.set_state(state["inner"])
