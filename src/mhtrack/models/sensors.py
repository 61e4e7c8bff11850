"""Sensor models: a Cartesian position sensor (P1 §1.1, eq. 2) and a 2-D polar radar (P2).

A polar radar measures range ``r`` and bearing ``b`` (clockwise from north, i.e. from the
+y axis, as radar azimuth is usually given) from its known position, with independent
Gaussian errors ``σr`` and ``σb``. Its plots are turned into Cartesian positions by the
**unbiased converted measurement** (UCM) with its measurement-conditioned covariance
(Bar-Shalom, Li & Kirubarajan, *Estimation with Applications to Tracking and Navigation*,
2001, §10.4.3; Mo, Song, Zhou, Sun & Bar-Shalom, IEEE T-AES 34(3), 1998). With
``θ = π/2 − b`` the mathematical angle, ``λ = exp(−σθ²/2)`` and ``λ' = exp(−2σθ²)``::

    x = λ⁻¹ r cos θ,   y = λ⁻¹ r sin θ        (debiased position, relative to the radar)
    Rxx = (λ⁻² − 2) r² cos²θ + ½ (r² + σr²)(1 + λ' cos 2θ)
    Ryy = (λ⁻² − 2) r² sin²θ + ½ (r² + σr²)(1 − λ' cos 2θ)
    Rxy = (λ⁻² − 2) r² cosθ sinθ + ½ (r² + σr²) λ' sin 2θ

The tracker then uses a linear Kalman update with the converted plot and this ``R``.

A :class:`RotatingRadar` is a polar radar whose beam turns: it sees a target once per
rotation, when the beam crosses it (:mod:`mhtrack.scenario.sweep` simulates it on the
WGS-84 ellipsoid). Real radars, as a sensors file describes them, are in
:mod:`mhtrack.models.radars`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mhtrack.errors import short_number
from mhtrack.models.clutter import ClutterPatch
from mhtrack.records import MAX_COORDINATE

#: Largest Cartesian ``sigma`` and polar ``sigma_range`` accepted (m): 1000 km, far beyond
#: any real sensor, and small enough that ``σ²`` and the plots stay finite.
MAX_SIGMA = 1e6
#: Largest polar ``sigma_bearing_deg`` accepted (degrees). The converted measurement divides
#: by ``λ = exp(−σθ²/2)``, which explodes for wide bearing errors (σθ = 1000° gives plots
#: at 1e68 m); beyond 30° a "radar" no longer gives a usable bearing.
MAX_SIGMA_BEARING_DEG = 30.0


def _in_range(value: object, hi: float) -> bool:
    """``value`` is a finite real number in ``(0, hi]``."""
    try:
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False
    return bool(np.isfinite(x)) and 0 < x <= hi


@dataclass(frozen=True)
class Observation:
    """What a sensor reports for a set of positions: Cartesian plots ``z`` (n, 2), their
    covariances ``R`` (n, 2, 2), and for polar sensors ``range_bearing`` (n, 2) in metres
    and degrees."""

    z: np.ndarray
    R: np.ndarray
    range_bearing: np.ndarray | None = None


@dataclass(frozen=True)
class CartesianSensor:
    """Position sensor ``z = Hx + w``, ``w ~ N(0, σ² I₂)`` (P1 eq. 2; P1 uses σ² = 10⁴ m²)."""

    id: int = 0
    sigma: float = 100.0
    kind: str = field(default="cartesian", init=False)

    def __post_init__(self) -> None:
        if not _in_range(self.sigma, MAX_SIGMA):
            raise ValueError(
                f"sensor {self.id}: sigma must be > 0 and <= {short_number(MAX_SIGMA)} m, "
                f"got {self.sigma}"
            )

    @property
    def R(self) -> np.ndarray:
        return np.eye(2) * self.sigma**2

    def observe(self, rng: np.random.Generator, positions: np.ndarray) -> Observation:
        """Noisy plots of true ``positions`` (n, 2)."""
        p = np.asarray(positions, float).reshape(-1, 2)
        z = p + rng.normal(scale=self.sigma, size=p.shape)
        return Observation(z, np.broadcast_to(self.R, (len(p), 2, 2)).copy())

    def place(self, z: np.ndarray) -> Observation:
        """Report plots exactly at ``z`` (used for clutter, which has no 'true' position)."""
        z = np.asarray(z, float).reshape(-1, 2)
        return Observation(z.copy(), np.broadcast_to(self.R, (len(z), 2, 2)).copy())


@dataclass(frozen=True)
class PolarRadar:
    """2-D radar at ``position`` measuring range (σ ``sigma_range`` m) and bearing
    (σ ``sigma_bearing_deg`` degrees, clockwise from north). P2: σr = 20 m, σθ = 0.3°."""

    id: int
    position: tuple[float, float] = (0.0, 0.0)
    sigma_range: float = 20.0
    sigma_bearing_deg: float = 0.3
    kind: str = field(default="polar", init=False)

    def __post_init__(self) -> None:
        if not _in_range(self.sigma_range, MAX_SIGMA):
            raise ValueError(
                f"sensor {self.id}: sigma_range must be > 0 and <= {short_number(MAX_SIGMA)} m, "
                f"got {self.sigma_range}"
            )
        if not _in_range(self.sigma_bearing_deg, MAX_SIGMA_BEARING_DEG):
            raise ValueError(
                f"sensor {self.id}: sigma_bearing_deg must be > 0 and <= "
                f"{short_number(MAX_SIGMA_BEARING_DEG)} degrees, got {self.sigma_bearing_deg}"
            )
        pos = tuple(float(v) for v in self.position)
        if len(pos) != 2 or not all(
            np.isfinite(v) and abs(v) <= MAX_COORDINATE for v in pos
        ):
            raise ValueError(
                f"sensor {self.id}: position must be two finite coordinates within "
                f"±{short_number(MAX_COORDINATE)} m, got {self.position!r}"
            )
        object.__setattr__(self, "position", pos)

    def to_polar(self, positions: np.ndarray) -> np.ndarray:
        """Exact ``(range m, bearing deg)`` of Cartesian ``positions`` (n, 2)."""
        d = np.asarray(positions, float).reshape(-1, 2) - np.asarray(self.position)
        r = np.hypot(d[:, 0], d[:, 1])
        b = np.degrees(np.arctan2(d[:, 0], d[:, 1])) % 360.0
        return np.column_stack((r, b))

    def convert(self, range_bearing: np.ndarray) -> Observation:
        """Unbiased converted measurement and its covariance (module docstring formulas)."""
        rb = np.asarray(range_bearing, float).reshape(-1, 2)
        r = rb[:, 0]
        th = np.pi / 2 - np.radians(rb[:, 1])
        s2 = np.radians(self.sigma_bearing_deg) ** 2
        lam = np.exp(-s2 / 2)
        lam2 = np.exp(-2 * s2)
        c, s = np.cos(th), np.sin(th)
        z = np.column_stack((r * c, r * s)) / lam + np.asarray(self.position)
        a = (lam**-2 - 2) * r**2
        b = 0.5 * (r**2 + self.sigma_range**2)
        R = np.empty((len(r), 2, 2))
        R[:, 0, 0] = a * c**2 + b * (1 + lam2 * np.cos(2 * th))
        R[:, 1, 1] = a * s**2 + b * (1 - lam2 * np.cos(2 * th))
        R[:, 0, 1] = R[:, 1, 0] = a * c * s + b * lam2 * np.sin(2 * th)
        return Observation(z, R, rb)

    def observe(self, rng: np.random.Generator, positions: np.ndarray) -> Observation:
        """Noisy range/bearing of true ``positions``, converted to Cartesian."""
        rb = self.to_polar(positions)
        rb[:, 0] += rng.normal(scale=self.sigma_range, size=len(rb))
        rb[:, 1] += rng.normal(scale=self.sigma_bearing_deg, size=len(rb))
        rb[:, 0] = np.abs(rb[:, 0])
        rb[:, 1] %= 360.0
        return self.convert(rb)

    def place(self, z: np.ndarray) -> Observation:
        """Report plots whose measured range/bearing point exactly at ``z`` (clutter)."""
        return self.convert(self.to_polar(z))


@dataclass(frozen=True, kw_only=True)
class RotatingRadar:
    """A 2-D radar whose beam turns clockwise with ``period`` (s); ``phase`` is the beam's
    bearing at ``t = 0`` (degrees clockwise from north), so at time ``t`` the beam points
    at ``β(t) = phase + 360 t / period`` (mod 360).

    Its site is ``lat``/``lon`` (WGS-84 degrees) or ``position`` (x, y m in the scenario's
    local frame), exactly one of them. It measures geodesic ground range (σ
    ``sigma_range`` m) and azimuth (σ ``sigma_bearing_deg``), sees only up to
    ``max_range`` (m, ``None``: unlimited), and draws its own clutter per rotation:
    ``clutter_rate`` plots uniform in range–azimuth over its coverage plus
    ``clutter_patches`` (:func:`~mhtrack.models.clutter.sample_range_azimuth`).

    Registration bias (simulation only, none by default): a target's plot reports
    ``r_m = range_gain · r + range_bias`` and ``θ_m = θ + azimuth_bias_deg`` before its
    noise (the range offset, gain and azimuth offset of :mod:`mhtrack.models.registration`).
    """

    id: int
    period: float
    sigma_range: float
    sigma_bearing_deg: float
    phase: float = 0.0
    lat: float | None = None
    lon: float | None = None
    position: tuple[float, float] | None = None
    max_range: float | None = None
    clutter_rate: float = 0.0
    clutter_patches: tuple[ClutterPatch, ...] = ()
    range_bias: float = 0.0
    range_gain: float = 1.0
    azimuth_bias_deg: float = 0.0
    kind: str = field(default="polar", init=False)

    def __post_init__(self) -> None:
        w = f"sensor {self.id}"
        for key in ("period", "sigma_range", "sigma_bearing_deg", "phase", "clutter_rate",
                    "lat", "lon", "max_range", "range_bias", "range_gain", "azimuth_bias_deg"):
            v = getattr(self, key)
            if v is None:
                continue
            try:
                x = float(v)
            except (TypeError, ValueError):
                raise ValueError(f"{w}: {key} must be a number, got {v!r}") from None
            if not np.isfinite(x):
                raise ValueError(f"{w}: {key} must be finite, got {v!r}")
            object.__setattr__(self, key, x)
        if not self.period > 0:
            raise ValueError(f"{w}: period must be > 0 s, got {self.period:g}")
        if not _in_range(self.sigma_range, MAX_SIGMA):
            raise ValueError(f"{w}: sigma_range must be > 0 and <= {short_number(MAX_SIGMA)} m, "
                             f"got {self.sigma_range}")
        if not _in_range(self.sigma_bearing_deg, MAX_SIGMA_BEARING_DEG):
            raise ValueError(f"{w}: sigma_bearing_deg must be > 0 and <= "
                             f"{short_number(MAX_SIGMA_BEARING_DEG)} degrees, "
                             f"got {self.sigma_bearing_deg}")
        if (self.lat is None) != (self.lon is None):
            raise ValueError(f"{w}: lat and lon give the site together")
        if (self.lat is None) == (self.position is None):
            raise ValueError(f"{w}: give the site once: lat/lon or position")
        if self.lat is not None and not (-90 <= self.lat <= 90 and -180 <= self.lon <= 180):
            raise ValueError(f"{w}: lat/lon must be within [-90, 90] x [-180, 180] degrees, "
                             f"got ({self.lat:g}, {self.lon:g})")
        if self.position is not None:
            pos = tuple(float(v) for v in self.position)
            if len(pos) != 2 or not all(np.isfinite(v) and abs(v) <= MAX_COORDINATE
                                        for v in pos):
                raise ValueError(f"{w}: position must be two finite coordinates within "
                                 f"±{short_number(MAX_COORDINATE)} m, got {self.position!r}")
            object.__setattr__(self, "position", pos)
        if self.max_range is not None and not self.max_range > 0:
            raise ValueError(f"{w}: max_range must be > 0 m, got {self.max_range:g}")
        if not 0.5 <= self.range_gain <= 2.0:
            raise ValueError(f"{w}: range_gain must be within [0.5, 2], got {self.range_gain:g}")
        if self.clutter_rate < 0:
            raise ValueError(f"{w}: clutter_rate must be >= 0, got {self.clutter_rate:g}")
        if self.clutter_rate > 0 and self.max_range is None:
            raise ValueError(f"{w}: clutter_rate > 0 needs max_range (the coverage the "
                             "uniform clutter spreads over)")
        patches = tuple(self.clutter_patches)
        if not all(isinstance(p, ClutterPatch) for p in patches):
            raise ValueError(f"{w}: clutter_patches must be ClutterPatch records")
        object.__setattr__(self, "clutter_patches", patches)

    @property
    def rate_deg(self) -> float:
        """The beam's turning rate ``ω = 360 / period`` (degrees per second)."""
        return 360.0 / self.period

    def beam(self, t: np.ndarray | float) -> np.ndarray:
        """The beam's bearing ``β(t) = (phase + ω t) mod 360`` (degrees) at times ``t``."""
        return np.mod(self.phase + self.rate_deg * np.asarray(t, float), 360.0)

    def mean_clutter(self) -> float:
        """Upper bound of the mean clutter count per rotation (patches before thinning)."""
        return self.clutter_rate + sum(p.rate for p in self.clutter_patches)


Sensor = CartesianSensor | PolarRadar | RotatingRadar
