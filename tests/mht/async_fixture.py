"""A small, self-contained simulation of rotating radars for the asynchronous MHT's tests
and benchmark (independent of :mod:`mhtrack.scenario`).

Radars at known positions in a flat local frame rotate clockwise with their own periods
and phases; each target's plot is timed when the beam crosses it (the crossing found by
fixed-point iteration of ``a(t) = θ(t)``), measured in range and bearing with Gaussian
errors and converted to ``x, y`` with the linearised covariance
``R = J diag(σr², σθ²) Jᵀ``, ``J = ∂(x, y)/∂(r, θ)``. Clutter is uniform in range and
azimuth, each clutter plot timed by its azimuth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mhtrack.frames import frame_lengths, make_frames
from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.records import PlotTable

ORIGIN = (46.8, 8.2)


@dataclass(frozen=True)
class Radar:
    id: int
    x: float
    y: float
    period: float
    phase_deg: float
    pd: float = 0.9
    sigma_range: float = 40.0
    sigma_bearing_deg: float = 0.15
    max_range: float = 60_000.0
    clutter_per_rotation: float = 20.0

    def sensor(self) -> RadarSensor:
        return RadarSensor(self.id, "polar", pd=self.pd, position=(self.x, self.y),
                           sigma_range=self.sigma_range,
                           sigma_bearing_deg=self.sigma_bearing_deg, period=self.period,
                           max_range=self.max_range)

    def beam(self, t: np.ndarray) -> np.ndarray:
        """Beam azimuth (degrees, unwrapped) at times ``t``."""
        return self.phase_deg + 360.0 * np.asarray(t) / self.period


def sensor_set(radars: list[Radar]) -> SensorSet:
    return SensorSet(ORIGIN, tuple(r.sensor() for r in radars))


def polar_plot(radar: Radar, r: np.ndarray, b_deg: np.ndarray) -> tuple[np.ndarray,
                                                                          np.ndarray]:
    """Positions (n, 2) and linearised covariances (n, 2, 2) of polar measurements."""
    b = np.radians(b_deg)
    z = np.column_stack((radar.x + r * np.sin(b), radar.y + r * np.cos(b)))
    J = np.zeros((r.size, 2, 2))
    J[:, 0, 0], J[:, 0, 1] = np.sin(b), r * np.cos(b)
    J[:, 1, 0], J[:, 1, 1] = np.cos(b), -r * np.sin(b)
    D = np.diag([radar.sigma_range**2, math.radians(radar.sigma_bearing_deg) ** 2])
    return z, J @ D @ np.swapaxes(J, 1, 2)


@dataclass(frozen=True)
class AsyncSim:
    plots: PlotTable
    sensors: SensorSet
    x0: np.ndarray  # (m, 4) target states at t = 0
    duration: float

    def truth_at(self, t: float) -> np.ndarray:
        x = self.x0
        return np.column_stack((x[:, 0] + x[:, 1] * t, x[:, 2] + x[:, 3] * t))


def default_targets(n: int = 5, seed: int = 0, extent: float = 25_000.0,
                    speeds: tuple[float, float] = (100.0, 250.0)) -> np.ndarray:
    """``n`` constant-velocity targets, ``[x, vx, y, vy]`` at t = 0, within ``±extent``."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform(-extent, extent, (n, 2))
    speed = rng.uniform(*speeds, n)
    head = rng.uniform(0, 2 * np.pi, n)
    return np.column_stack((pos[:, 0], speed * np.sin(head), pos[:, 1], speed * np.cos(head)))


def default_radars() -> list[Radar]:
    return [Radar(1, -15_000.0, -5_000.0, period=4.0, phase_deg=10.0),
            Radar(2, 20_000.0, 10_000.0, period=6.0, phase_deg=200.0, pd=0.85,
                  sigma_range=60.0, sigma_bearing_deg=0.2)]


def simulate_async(radars: list[Radar] | None = None, x0: np.ndarray | None = None,
                   duration: float = 120.0, seed: int = 1, clutter: bool = True) -> AsyncSim:
    """Timed plots of ``radars`` (default :func:`default_radars`) seeing targets ``x0``
    (default :func:`default_targets`) for ``duration`` seconds."""
    radars = default_radars() if radars is None else radars
    x0 = default_targets() if x0 is None else np.asarray(x0, float)
    rng = np.random.default_rng(seed)
    cols: dict[str, list[np.ndarray]] = {k: [] for k in ("t", "s", "z", "R", "o")}
    for rad in radars:
        omega = 360.0 / rad.period
        n_rot = math.ceil(duration / rad.period) + 1
        k0 = math.floor(rad.phase_deg / 360.0)  # rotation k: beam in [360k, 360(k+1))
        for k in range(n_rot):
            t_start = (360.0 * (k + k0) - rad.phase_deg) / omega
            for j, x in enumerate(x0):
                t = t_start
                for _ in range(4):  # beam(t) = bearing of the target at t
                    px, py = x[0] + x[1] * t - rad.x, x[2] + x[3] * t - rad.y
                    th = math.degrees(math.atan2(px, py)) % 360.0
                    t = t_start + ((th - rad.beam(t_start)) % 360.0) / omega
                px, py = x[0] + x[1] * t - rad.x, x[2] + x[3] * t - rad.y
                rng_m = math.hypot(px, py)
                if not (0 <= t < duration) or rng_m > rad.max_range or rng.random() >= rad.pd:
                    continue
                r = np.array([rng_m + rad.sigma_range * rng.standard_normal()])
                b = np.array([math.degrees(math.atan2(px, py))
                              + rad.sigma_bearing_deg * rng.standard_normal()])
                z, R = polar_plot(rad, r, b)
                for key, v in (("t", [t]), ("s", [rad.id]), ("z", z), ("R", R), ("o", [j])):
                    cols[key].append(np.asarray(v))
            if clutter:
                m = rng.poisson(rad.clutter_per_rotation)
                az = rng.uniform(0, 360, m)
                r = rng.uniform(1000.0, rad.max_range, m)
                t = t_start + ((az - rad.beam(t_start)) % 360.0) / omega
                ok = (t >= 0) & (t < duration)
                z, R = polar_plot(rad, r[ok], az[ok])
                for key, v in (("t", t[ok]), ("s", np.full(ok.sum(), rad.id)), ("z", z),
                               ("R", R), ("o", np.full(ok.sum(), -1))):
                    cols[key].append(np.asarray(v))
    t = np.concatenate(cols["t"]).astype(float)
    s = np.concatenate(cols["s"]).astype(np.int64)
    z = np.concatenate(cols["z"]).reshape(-1, 2)
    R = np.concatenate(cols["R"]).reshape(-1, 2, 2)
    o = np.concatenate(cols["o"]).astype(np.int64)
    return AsyncSim(timed_table(t, s, z, R, o, radars), sensor_set(radars), x0, duration)


def timed_table(t: np.ndarray, s: np.ndarray, z: np.ndarray, R: np.ndarray, o: np.ndarray,
                radars: list[Radar]) -> PlotTable:
    """A timed :class:`PlotTable` cut into frames (:func:`mhtrack.frames.make_frames`)."""
    frame, order = make_frames(t, s, frame_lengths({r.id: r.period for r in radars}))
    return PlotTable(scan=frame[order], time=t[order], sensor=s[order], x=z[order, 0],
                     y=z[order, 1], origin=o[order], R=R[order], timed=True)
