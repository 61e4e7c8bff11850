"""A changing clutter scene seen by rotating radars: weather cells that drift with the wind
and grow and fade, ground clutter fixed round each site, a sea-clutter band whose sea state
rises, and a sudden burst in one sector (``docs/clutter.md``, *Clutter scenes*).

Every component gives, for one radar at plane site ``s`` and time ``t``, a mean number of
plots per rotation ``N(t)`` and a plane density ``f(x; t)`` (per m², integrating to 1 over
the plane), so that its intensity per m² per rotation is ``κ(x, t) = N(t) f(x; t)``. With
``r = |x − s|`` and ``θ`` the plane bearing of ``x`` from ``s`` (clockwise from north):

* :class:`WeatherCell` — ``N(t) = N₀ sin²(π (t − t_on)/(t_off − t_on))`` on
  ``[t_on, t_off]`` (0 outside: the cell grows, peaks and fades),
  ``f = N(x; c(t), σ(t)² I)`` with ``c(t) = c₀ + v t`` (drift with the wind ``v``) and
  ``σ(t) = σ₀ + g (t − t_on)`` for ``t > t_on`` (growth ``g >= 0``);
* :class:`GroundClutter` — ``N`` constant, ``f = exp(−r²/2L²)/(2π L²) ·
  (1 + a cos(m(θ − θ₀)))``: dense at short range (a Rayleigh range law of scale ``L``),
  uneven in bearing (``m`` lobes, ripple ``a < 1``; the cosine integrates to 0 over θ);
* :class:`SeaBand` — ``N(t)`` linear from ``N₀`` at ``t₀`` to ``N₁`` at ``t₁`` (constant
  outside), range ``~ N(r_c, σ_r²)``, bearing uniform over the sector ``[θ₁, θ₁ + Δθ]``:
  ``f = φ(r; r_c, σ_r) / (Δθ r)`` (``Δθ`` in radians; ``1/r`` is the Jacobian of plane
  polar coordinates, ``dA = r dr dθ``);
* :class:`Burst` — ``N`` on ``[t_on, t_on + d)`` only, range uniform on
  ``[r_min, r_max]``, bearing uniform over a sector: ``f = 1/((r_max − r_min) Δθ r)``.

Sampling draws ``Poisson(N(t))`` points from ``f``; the radar keeps those within its
``max_range`` (a Poisson thinning: the kept count is Poisson with mean ``∫_cover κ``), and
plots at ``r <= 0`` (a sea band's normal tail) are dropped the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * math.pi


def _finite(obj: object, *keys: str) -> None:
    for k in keys:
        v = float(getattr(obj, k))
        if not math.isfinite(v):
            raise ValueError(f"{k}: must be finite, got {v}")
        object.__setattr__(obj, k, v)


def _positive(obj: object, *keys: str) -> None:
    for k in keys:
        if not getattr(obj, k) > 0:
            raise ValueError(f"{k}: must be > 0, got {getattr(obj, k):g}")


def _non_negative(obj: object, *keys: str) -> None:
    for k in keys:
        if not getattr(obj, k) >= 0:
            raise ValueError(f"{k}: must be >= 0, got {getattr(obj, k):g}")


def polar_about(xy: np.ndarray, site: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """``(r, θ)`` of plane points ``xy`` (n, 2) about ``site``: distance (m) and bearing
    (radians in ``[0, 2π)``, clockwise from grid north)."""
    xy = np.asarray(xy, float).reshape(-1, 2)
    dx, dy = xy[:, 0] - site[0], xy[:, 1] - site[1]
    return np.hypot(dx, dy), np.mod(np.arctan2(dx, dy), TWO_PI)


def _from_polar(r: np.ndarray, theta: np.ndarray, site: tuple[float, float]) -> np.ndarray:
    return np.column_stack((site[0] + r * np.sin(theta), site[1] + r * np.cos(theta)))


def _in_sector(theta: np.ndarray, start: float, width: float) -> np.ndarray:
    return np.mod(theta - start, TWO_PI) <= width


@dataclass(frozen=True)
class WeatherCell:
    """A rain cell drifting with the wind, growing, then fading (module docstring).
    ``x, y``: centre at ``t = 0`` (m); ``vx, vy``: drift (m/s); ``sigma``: σ₀ (m);
    ``growth``: g (m/s); ``peak``: N₀ (plots per rotation); ``t_on, t_off`` (s)."""

    x: float
    y: float
    vx: float
    vy: float
    sigma: float
    growth: float
    peak: float
    t_on: float
    t_off: float

    def __post_init__(self) -> None:
        _finite(self, "x", "y", "vx", "vy", "sigma", "growth", "peak", "t_on", "t_off")
        _positive(self, "sigma")
        _non_negative(self, "growth", "peak")
        if not self.t_off > self.t_on:
            raise ValueError(f"t_off: must be > t_on ({self.t_off:g} <= "
                             f"{self.t_on:g})")

    def centre(self, t: float) -> tuple[float, float]:
        """``c(t) = c₀ + v t``."""
        return (self.x + self.vx * t, self.y + self.vy * t)

    def sigma_at(self, t: float) -> float:
        """``σ(t) = σ₀ + g·max(t − t_on, 0)``."""
        return self.sigma + self.growth * max(t - self.t_on, 0.0)

    def rate(self, t: float) -> float:
        if not self.t_on <= t <= self.t_off:
            return 0.0
        return self.peak * math.sin(math.pi * (t - self.t_on) / (self.t_off - self.t_on)) ** 2

    def density(self, xy: np.ndarray, t: float, site: tuple[float, float]) -> np.ndarray:
        xy = np.asarray(xy, float).reshape(-1, 2)
        cx, cy = self.centre(t)
        s2 = self.sigma_at(t) ** 2
        d2 = (xy[:, 0] - cx) ** 2 + (xy[:, 1] - cy) ** 2
        return np.exp(-0.5 * d2 / s2) / (TWO_PI * s2)

    def sample(self, rng: np.random.Generator, n: int, t: float,
               site: tuple[float, float]) -> np.ndarray:
        return np.asarray(self.centre(t)) + self.sigma_at(t) * rng.normal(size=(n, 2))


@dataclass(frozen=True)
class GroundClutter:
    """Fixed ground clutter round the radar's site (module docstring): ``rate`` N per
    rotation, range scale ``scale`` L (m), ``lobes`` m, ``ripple`` a in [0, 1),
    ``phase_deg`` θ₀."""

    rate_per_rotation: float
    scale: float
    ripple: float = 0.0
    lobes: int = 1
    phase_deg: float = 0.0

    def __post_init__(self) -> None:
        _finite(self, "rate_per_rotation", "scale", "ripple", "phase_deg")
        _positive(self, "scale")
        _non_negative(self, "rate_per_rotation")
        if not 0.0 <= self.ripple < 1.0:
            raise ValueError(f"ripple: must be in [0, 1), got {self.ripple:g}")
        if isinstance(self.lobes, bool) or int(self.lobes) != self.lobes or self.lobes < 1:
            raise ValueError(f"lobes: must be an integer >= 1, got {self.lobes}")
        object.__setattr__(self, "lobes", int(self.lobes))

    def rate(self, t: float) -> float:
        return self.rate_per_rotation

    def _angular(self, theta: np.ndarray) -> np.ndarray:
        return 1.0 + self.ripple * np.cos(self.lobes * (theta - math.radians(self.phase_deg)))

    def density(self, xy: np.ndarray, t: float, site: tuple[float, float]) -> np.ndarray:
        r, theta = polar_about(xy, site)
        L2 = self.scale ** 2
        return np.exp(-0.5 * r * r / L2) / (TWO_PI * L2) * self._angular(theta)

    def sample(self, rng: np.random.Generator, n: int, t: float,
               site: tuple[float, float]) -> np.ndarray:
        r = self.scale * np.sqrt(-2.0 * np.log1p(-rng.random(n)))  # Rayleigh(L)
        theta = np.zeros(0)
        while len(theta) < n:  # rejection from the uniform bearing, bound 1 + a
            cand = TWO_PI * rng.random(n)
            ok = rng.random(n) * (1.0 + self.ripple) <= self._angular(cand)
            theta = np.concatenate((theta, cand[ok]))
        return _from_polar(r, theta[:n], site)


@dataclass(frozen=True)
class SeaBand:
    """Sea clutter in a band of ranges over a sector of bearings, its sea state rising
    (module docstring): ``rate_start`` N₀ at ``t_start``, ``rate_end`` N₁ at ``t_end``;
    range ``~ N(range, sigma_range²)``; bearings ``[bearing_deg, bearing_deg + width_deg]``."""

    rate_start: float
    rate_end: float
    t_start: float
    t_end: float
    range: float
    sigma_range: float
    bearing_deg: float
    width_deg: float

    def __post_init__(self) -> None:
        _finite(self, "rate_start", "rate_end", "t_start", "t_end", "range", "sigma_range",
                "bearing_deg", "width_deg")
        _non_negative(self, "rate_start", "rate_end")
        _positive(self, "range", "sigma_range", "width_deg")
        if not self.t_end > self.t_start:
            raise ValueError("t_end: must be > t_start")
        if self.width_deg > 360.0:
            raise ValueError(f"width_deg: must be <= 360, got {self.width_deg:g}")

    def rate(self, t: float) -> float:
        u = min(max((t - self.t_start) / (self.t_end - self.t_start), 0.0), 1.0)
        return self.rate_start + u * (self.rate_end - self.rate_start)

    def density(self, xy: np.ndarray, t: float, site: tuple[float, float]) -> np.ndarray:
        r, theta = polar_about(xy, site)
        width = math.radians(self.width_deg)
        phi = np.exp(-0.5 * ((r - self.range) / self.sigma_range) ** 2) / (
            math.sqrt(TWO_PI) * self.sigma_range)
        inside = _in_sector(theta, math.radians(self.bearing_deg), width) & (r > 0)
        return np.where(inside, phi / (width * np.maximum(r, 1e-300)), 0.0)

    def sample(self, rng: np.random.Generator, n: int, t: float,
               site: tuple[float, float]) -> np.ndarray:
        r = self.range + self.sigma_range * rng.normal(size=n)
        theta = math.radians(self.bearing_deg) + math.radians(self.width_deg) * rng.random(n)
        keep = r > 0  # the normal's tail below 0: a thinning (module docstring)
        return _from_polar(r[keep], theta[keep], site)


@dataclass(frozen=True)
class Burst:
    """A sudden burst in one sector for ``duration`` s from ``t_on`` (module docstring):
    ``rate_per_rotation`` N, range uniform on ``[range_min, range_max]``, bearings
    ``[bearing_deg, bearing_deg + width_deg]``."""

    rate_per_rotation: float
    t_on: float
    duration: float
    bearing_deg: float
    width_deg: float
    range_min: float
    range_max: float

    def __post_init__(self) -> None:
        _finite(self, "rate_per_rotation", "t_on", "duration", "bearing_deg", "width_deg",
                "range_min", "range_max")
        _non_negative(self, "rate_per_rotation")
        _positive(self, "duration", "width_deg", "range_min")
        if not self.range_max > self.range_min:
            raise ValueError("range_max: must be > range_min")
        if self.width_deg > 360.0:
            raise ValueError(f"width_deg: must be <= 360, got {self.width_deg:g}")

    def rate(self, t: float) -> float:
        return self.rate_per_rotation if self.t_on <= t < self.t_on + self.duration else 0.0

    def density(self, xy: np.ndarray, t: float, site: tuple[float, float]) -> np.ndarray:
        r, theta = polar_about(xy, site)
        width = math.radians(self.width_deg)
        inside = (_in_sector(theta, math.radians(self.bearing_deg), width)
                  & (r >= self.range_min) & (r <= self.range_max))
        return np.where(inside, 1.0 / ((self.range_max - self.range_min) * width
                                       * np.maximum(r, self.range_min)), 0.0)

    def sample(self, rng: np.random.Generator, n: int, t: float,
               site: tuple[float, float]) -> np.ndarray:
        r = self.range_min + (self.range_max - self.range_min) * rng.random(n)
        theta = math.radians(self.bearing_deg) + math.radians(self.width_deg) * rng.random(n)
        return _from_polar(r, theta, site)


SceneComponent = WeatherCell | GroundClutter | SeaBand | Burst
#: Component kind (dict form) → class.
COMPONENT_KINDS: dict[str, type] = {"weather": WeatherCell, "ground": GroundClutter,
                                    "sea": SeaBand, "burst": Burst}


@dataclass(frozen=True)
class ScenePart:
    """One component and the radars that see it (``radars``: sensor ids; ``None``: every
    radar). A site-bound component (ground, sea, burst) is placed about each of its
    radars' own site; a weather cell is in the plane, the same for all."""

    component: SceneComponent
    radars: tuple[int, ...] | None = None

    def sees(self, sensor_id: int) -> bool:
        return self.radars is None or int(sensor_id) in self.radars


@dataclass(frozen=True)
class ClutterScene:
    """A named set of :class:`ScenePart` s (module docstring). Per radar and time:
    ``rate(sid, t) = Σ N_c(t)`` and ``intensity(sid, xy, t, site) = Σ N_c(t) f_c(x; t)``
    (per m² per rotation, before the radar's ``max_range``)."""

    name: str
    parts: tuple[ScenePart, ...]

    def seen_by(self, sensor_id: int) -> tuple[SceneComponent, ...]:
        return tuple(p.component for p in self.parts if p.sees(sensor_id))

    def rate(self, sensor_id: int, t: float) -> float:
        return float(sum(c.rate(t) for c in self.seen_by(sensor_id)))

    def mean_rate(self, sensor_id: int, start: float, end: float, n: int = 64) -> float:
        """Mean of ``rate(sid, t)`` over ``n`` midpoints of ``[start, end]`` (sizes only)."""
        ts = start + (end - start) * (np.arange(n) + 0.5) / n
        return float(np.mean([self.rate(sensor_id, float(t)) for t in ts]))

    def intensity(self, sensor_id: int, xy: np.ndarray, t: float,
                  site: tuple[float, float]) -> np.ndarray:
        xy = np.asarray(xy, float).reshape(-1, 2)
        out = np.zeros(len(xy))
        for c in self.seen_by(sensor_id):
            n = c.rate(t)
            if n > 0:
                out += n * c.density(xy, t, site)
        return out

    def sample(self, rng: np.random.Generator, sensor_id: int, t: float,
               site: tuple[float, float]) -> np.ndarray:
        """One rotation's scene clutter of radar ``sensor_id`` at ``t``: plane points
        (n, 2), each component in turn a ``Poisson(N_c(t))`` draw from ``f_c``."""
        parts = [np.zeros((0, 2))]
        for c in self.seen_by(sensor_id):
            n = c.rate(t)
            k = int(rng.poisson(n)) if n > 0 else 0
            if k:
                parts.append(c.sample(rng, k, t, site))
        return np.concatenate(parts)
