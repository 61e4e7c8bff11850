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

Real sensors, as a sensors file describes them (docs/file-formats.md, "Sensors file"), are
:class:`RadarSensor` records gathered in a :class:`SensorSet`: geodetic sites, errors,
``P_D``, rotation period and instrumented range. Their polar plots are converted on the
WGS-84 ellipsoid by :mod:`mhtrack.models.geodesy`.
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.errors import short_number
from mhtrack.records import MAX_COORDINATE

if TYPE_CHECKING:
    from mhtrack.models.geodesy import LocalFrame

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


Sensor = CartesianSensor | PolarRadar


#: The kinds of real sensor a sensors file may declare.
RADAR_KINDS = ("polar", "cartesian")


class SensorFieldError(ValueError):
    """A :class:`RadarSensor` or :class:`SensorSet` field out of its domain: ``where``
    (``"sensor 3"``, ``"sensors[1]"``, ``"origin"``), the field ``key``, and for a
    :class:`SensorSet` the sensor's 0-based ``index`` — so that a file reader can point
    at the line."""

    def __init__(self, where: str, key: str, message: str, index: int | None = None) -> None:
        super().__init__(f"{where}: {key}: {message}")
        self.where = where
        self.key = key
        self.message = message
        self.index = index


def check_latlon(where: str, lat: float, lon: float) -> None:
    """Raise :class:`SensorFieldError` unless ``lat ∈ [−90, 90]`` and ``lon ∈ [−180, 180]``."""
    if not (np.isfinite(lat) and -90.0 <= lat <= 90.0):
        raise SensorFieldError(where, "lat", f"latitude must be within [-90, 90] degrees, "
                               f"got {lat:g}")
    if not (np.isfinite(lon) and -180.0 <= lon <= 180.0):
        raise SensorFieldError(where, "lon", f"longitude must be within [-180, 180] degrees, "
                               f"got {lon:g}")


@dataclass(frozen=True)
class RadarSensor:
    """A real sensor: a polar radar at a geodetic site (or a Cartesian position sensor).

    ``lat``/``lon`` (WGS-84 degrees) or ``position`` (x, y metres in the local frame) give
    the site; ``alt`` its height (m, kept for output, unused by the 2-D conversions). Polar
    sensors measure geodesic ground range (σ ``sigma_range`` m) and azimuth (σ
    ``sigma_bearing_deg``); Cartesian ones ``x, y`` with σ ``sigma`` m. ``pd`` is the
    detection probability, ``period`` the rotation period (s), ``max_range`` the
    instrumented range (m). Out-of-domain fields raise :class:`SensorFieldError`.
    """

    id: int
    kind: str
    _: KW_ONLY
    pd: float
    lat: float | None = None
    lon: float | None = None
    alt: float | None = None
    position: tuple[float, float] | None = None
    sigma_range: float | None = None
    sigma_bearing_deg: float | None = None
    sigma: float | None = None
    period: float | None = None
    max_range: float | None = None

    def __post_init__(self) -> None:
        w = f"sensor {self.id}"
        if isinstance(self.id, bool) or not isinstance(self.id, int | np.integer):
            raise SensorFieldError(w, "id", f"must be an integer, got {self.id!r}")
        object.__setattr__(self, "id", int(self.id))
        if self.kind not in RADAR_KINDS:
            raise SensorFieldError(w, "kind", f"must be 'polar' or 'cartesian', got {self.kind!r}")
        for key in ("pd", "lat", "lon", "alt", "sigma_range", "sigma_bearing_deg", "sigma",
                    "period", "max_range"):
            v = getattr(self, key)
            if v is not None:
                object.__setattr__(self, key, float(v))
                if not np.isfinite(float(v)):
                    raise SensorFieldError(w, key, f"must be finite, got {v}")
        if (self.lat is None) != (self.lon is None):
            missing = "lon" if self.lon is None else "lat"
            raise SensorFieldError(w, missing, "missing: lat and lon give the site together")
        if self.lat is not None:
            check_latlon(w, self.lat, self.lon)  # type: ignore[arg-type]
        if self.position is not None:
            if self.lat is not None:
                raise SensorFieldError(w, "position", "give the site once: lat/lon or position")
            pos = tuple(float(v) for v in self.position)
            if len(pos) != 2 or not all(np.isfinite(v) and abs(v) <= MAX_COORDINATE
                                        for v in pos):
                raise SensorFieldError(w, "position", "must be two finite coordinates within "
                                       f"±{short_number(MAX_COORDINATE)} m, got {self.position!r}")
            object.__setattr__(self, "position", pos)
        self._check_errors()
        if not 0.0 < self.pd <= 1.0:
            raise SensorFieldError(w, "pd", f"must be in (0, 1], got {self.pd:g}")
        for key in ("period", "max_range"):
            v = getattr(self, key)
            if v is not None and v <= 0:
                raise SensorFieldError(w, key, f"must be > 0, got {v:g}")

    def _check_errors(self) -> None:
        """The error keys of the sensor's kind are present and in range; the other kind's
        are absent."""
        w = f"sensor {self.id}"
        if self.kind == "polar":
            limits = {"sigma_range": (MAX_SIGMA, "m"),
                      "sigma_bearing_deg": (MAX_SIGMA_BEARING_DEG, "degrees")}
            other = ("sigma",)
            if not self.has_site:
                raise SensorFieldError(w, "lat", "a polar sensor needs its site: lat and lon, "
                                       "or position = [x, y]")
        else:
            limits = {"sigma": (MAX_SIGMA, "m")}
            other = ("sigma_range", "sigma_bearing_deg")
        for key in other:
            if getattr(self, key) is not None:
                raise SensorFieldError(w, key, f"not used by a {self.kind} sensor")
        for key, (hi, unit) in limits.items():
            v = getattr(self, key)
            if v is None:
                raise SensorFieldError(w, key, f"missing: required for a {self.kind} sensor")
            if not 0 < v <= hi:
                raise SensorFieldError(w, key, f"must be > 0 and <= {short_number(hi)} {unit}, "
                                       f"got {v:g}")

    @property
    def has_site(self) -> bool:
        """The sensor's site is given (lat/lon or position)."""
        return self.lat is not None or self.position is not None


@dataclass(frozen=True)
class SensorSet:
    """The sensors of a data set and the origin of the local east-north frame.

    ``origin`` is ``(lat, lon)`` (WGS-84 degrees) or ``None``: then the frame is centred on
    the first sensor that has ``lat``/``lon``. Ids are unique; a sensor placed by
    ``position`` while it is polar needs a geodetic frame (origin or a lat/lon site) to
    convert its plots on the ellipsoid.
    """

    origin: tuple[float, float] | None
    sensors: tuple[RadarSensor, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "sensors", tuple(self.sensors))
        if self.origin is not None:
            lat, lon = (float(v) for v in self.origin)
            check_latlon("origin", lat, lon)
            object.__setattr__(self, "origin", (lat, lon))
        seen: dict[int, int] = {}
        for i, s in enumerate(self.sensors):
            if s.id in seen:
                raise SensorFieldError(f"sensors[{i}]", "id", f"duplicate id {s.id} (also "
                                       f"sensors[{seen[s.id]}])", index=i)
            seen[s.id] = i
        if self.reference is None:
            for i, s in enumerate(self.sensors):
                if s.kind == "polar":
                    raise SensorFieldError(
                        f"sensors[{i}]", "position",
                        "a polar sensor placed by position needs [origin] (or a sensor with "
                        "lat/lon) to put its range and bearing on the ellipsoid", index=i)

    @property
    def reference(self) -> tuple[float, float] | None:
        """The frame's tangent point: ``origin``, else the first lat/lon site, else None."""
        if self.origin is not None:
            return self.origin
        for s in self.sensors:
            if s.lat is not None:
                return (s.lat, s.lon)  # type: ignore[return-value]
        return None

    @property
    def ids(self) -> tuple[int, ...]:
        return tuple(s.id for s in self.sensors)

    def sensor(self, sensor_id: int) -> RadarSensor:
        """The sensor with this id (``KeyError`` if none)."""
        for s in self.sensors:
            if s.id == sensor_id:
                return s
        raise KeyError(f"unknown sensor {sensor_id} (known sensors: "
                       f"{', '.join(str(i) for i in self.ids)})")

    @cached_property
    def _frame(self) -> LocalFrame:
        from mhtrack.models.geodesy import LocalFrame  # pyproj is imported only when used

        ref = self.reference
        if ref is None:
            raise ValueError("no geodetic reference: give [origin] or a sensor's lat/lon")
        return LocalFrame(*ref)

    def frame(self) -> LocalFrame:
        """The local east-north frame (:class:`~mhtrack.models.geodesy.LocalFrame`)."""
        return self._frame

    def site_xy(self, sensor_id: int) -> tuple[float, float]:
        """The sensor's site in the local frame (m)."""
        s = self.sensor(sensor_id)
        if s.position is not None:
            return s.position
        if s.lat is None:
            raise ValueError(f"sensor {sensor_id} has no site")
        x, y = self.frame().to_local(s.lat, s.lon)
        return float(x), float(y)

    def site_latlon(self, sensor_id: int) -> tuple[float, float]:
        """The sensor's site in WGS-84 degrees (a ``position`` is carried to the ellipsoid)."""
        s = self.sensor(sensor_id)
        if s.lat is not None:
            return s.lat, s.lon  # type: ignore[return-value]
        if s.position is None:
            raise ValueError(f"sensor {sensor_id} has no site")
        lat, lon = self.frame().to_geodetic(*s.position)
        return float(lat), float(lon)
