"""Real radars as a sensors file describes them (docs/file-formats.md, "Sensors file").

A :class:`RadarSensor` is one radar: its geodetic site (or a position in the local frame),
its errors (``σr``, ``σθ`` for a polar radar, ``σ`` for a Cartesian sensor), ``P_D``,
rotation period and instrumented range; a :class:`SensorSet` gathers them with the origin
of the local east-north frame. Their polar plots are converted on the WGS-84 ellipsoid by
:mod:`mhtrack.models.geodesy`. Each record checks its own fields and raises
:class:`SensorFieldError` naming the field, so that a file reader can point at the line.
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.errors import short_number
from mhtrack.models.sensors import MAX_SIGMA, MAX_SIGMA_BEARING_DEG
from mhtrack.records import MAX_COORDINATE

if TYPE_CHECKING:
    from mhtrack.models.geodesy import LocalFrame


#: The kinds of real sensor a sensors file may declare: a rotating radar (range and
#: azimuth), a Cartesian position sensor, an ADS-B ground station (CAT021: each report
#: its own WGS-84 position and accuracy).
RADAR_KINDS = ("polar", "cartesian", "adsb")
#: Lowest and highest site altitude (m): no land lies below the Dead Sea shore (−430 m),
#: and above 100 km (the Kármán line) a sensor is a satellite, not a site.
MIN_ALT_M, MAX_ALT_M = -500.0, 100_000.0
#: Farthest a site may lie from the local frame's origin (m). The azimuthal equidistant
#: plane stretches lengths across the line to its origin by ``s/m12 ≈ 1 + s²/6R²``
#: (docs/geodesy.md): 3.7 % at 3 000 km, ``π/2`` at a quarter meridian, and without
#: bound towards the antipode, where plots would be silently misplaced.
MAX_SITE_DISTANCE_M = 3e6
#: Largest instrumented range (m): 20 000 km, about half a meridian (the plots reader's
#: bound on a range).
MAX_RANGE_M = 2e7
#: Names of the plot types a polar radar may give its own errors and ``P_D``
#: (:data:`mhtrack.attributes.PLOT_TYPES` codes 1–4: PSR only, SSR only, PSR + SSR, Mode S).
PLOT_TYPE_NAMES = {"primary": 1, "secondary": 2, "combined": 3, "mode_s": 4}
#: The keys of one plot type's table.
PLOT_TYPE_KEYS = ("pd", "sigma_range", "sigma_bearing_deg")
#: Smallest errors accepted: ``σr``, ``σ`` ≥ 1 nm, ``σθ`` ≥ 10⁻¹² degree — far below any
#: sensor (noise-free test geometries use them); smaller ones make ``σ²`` underflow
#: towards 0 in float64 and the plots' covariances singular (1e-300 gave 0).
MIN_SIGMA_M, MIN_SIGMA_BEARING_DEG = 1e-9, 1e-12


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
    the site (a polar radar without one takes the site it sends in ASTERIX CAT034
    I034/120 when its recording is read, :mod:`mhtrack.io.asterix.sites`; its plots in a
    plots table are refused); ``alt`` its height (m, kept for output, unused by the 2-D
    conversions). Polar sensors measure geodesic ground range (σ ``sigma_range`` m) and azimuth (σ
    ``sigma_bearing_deg``); Cartesian ones ``x, y`` with σ ``sigma`` m; ADS-B stations
    (``adsb``) relay WGS-84 positions, each with its own σ (``sigma``, optional, stands in
    for reports without an accuracy). ``pd`` is the
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
    #: Per plot type (:data:`PLOT_TYPE_NAMES`) the errors and ``P_D`` that replace the
    #: sensor's own for plots of that type: ``(name, pd, sigma_range, sigma_bearing_deg)``,
    #: ``None`` where the sensor's applies (polar radars only; empty: every plot alike).
    plot_types: tuple[tuple[str, float | None, float | None, float | None], ...] = ()

    def __post_init__(self) -> None:
        w = f"sensor {self.id}"
        if isinstance(self.id, bool) or not isinstance(self.id, int | np.integer):
            raise SensorFieldError(w, "id", f"must be an integer, got {self.id!r}")
        object.__setattr__(self, "id", int(self.id))
        if self.kind not in RADAR_KINDS:
            raise SensorFieldError(w, "kind", "must be 'polar', 'cartesian' or 'adsb', got "
                                   f"{self.kind!r}")
        for key in ("pd", "lat", "lon", "alt", "sigma_range", "sigma_bearing_deg", "sigma",
                    "period", "max_range"):
            v = getattr(self, key)
            if v is not None:
                object.__setattr__(self, key, float(v))
                if not np.isfinite(float(v)):
                    raise SensorFieldError(w, key, f"must be finite, got {v}")
        if self.alt is not None and not MIN_ALT_M <= self.alt <= MAX_ALT_M:
            raise SensorFieldError(w, "alt", f"altitude {self.alt:g} m is not physically "
                                   f"possible for a site (expected [{MIN_ALT_M:g}, "
                                   f"{MAX_ALT_M:g}] m; a unit error?)")
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
            if float(np.hypot(*pos)) > MAX_SITE_DISTANCE_M:
                raise SensorFieldError(w, "position", f"site {np.hypot(*pos) / 1e3:.0f} km "
                                       "from the frame's origin, farther than "
                                       f"{MAX_SITE_DISTANCE_M / 1e3:.0f} km (the local "
                                       "plane cannot hold it)")
            object.__setattr__(self, "position", pos)
        self._check_errors()
        if not 0.0 < self.pd <= 1.0:
            raise SensorFieldError(w, "pd", f"must be in (0, 1], got {self.pd:g}")
        for key in ("period", "max_range"):
            v = getattr(self, key)
            if v is not None and v <= 0:
                raise SensorFieldError(w, key, f"must be > 0, got {v:g}")
        if self.max_range is not None and self.max_range > MAX_RANGE_M:
            raise SensorFieldError(w, "max_range", f"{self.max_range:g} m is beyond "
                                   f"{MAX_RANGE_M / 1e3:.0f} km, half-way round the Earth")
        self._check_plot_types()

    def _check_plot_types(self) -> None:
        """Each plot type's table: a known type, once, on a polar radar, values in the
        ranges of the sensor's own keys."""
        w = f"sensor {self.id}"
        seen: set[str] = set()
        out = []
        for entry in self.plot_types:
            name, *values = entry
            if name not in PLOT_TYPE_NAMES:
                raise SensorFieldError(w, str(name), "unknown plot type; known: "
                                       f"{', '.join(PLOT_TYPE_NAMES)}")
            if name in seen:
                raise SensorFieldError(w, name, "given twice")
            seen.add(name)
            if self.kind != "polar":
                raise SensorFieldError(w, name, "per-plot-type errors and P_D apply to a "
                                       f"polar radar's plots, not to a {self.kind} sensor")
            limits = {"pd": (0.0, 1.0, ""), "sigma_range": (MIN_SIGMA_M, MAX_SIGMA, " m"),
                      "sigma_bearing_deg": (MIN_SIGMA_BEARING_DEG, MAX_SIGMA_BEARING_DEG,
                                            " degrees")}
            clean = []
            for key, v in zip(PLOT_TYPE_KEYS, values, strict=True):
                if v is not None:
                    v = float(v)
                    lo, hi, unit = limits[key]
                    bad = not (lo < v <= hi) if key == "pd" else not (lo <= v <= hi)
                    if not np.isfinite(v) or bad:
                        span = "(0, 1]" if key == "pd" else \
                            f"[{short_number(lo)}, {short_number(hi)}]"
                        raise SensorFieldError(w, f"{name}.{key}", f"must be in {span}{unit},"
                                               f" got {v:g}")
                clean.append(v)
            out.append((name, *clean))
        object.__setattr__(self, "plot_types", tuple(out))

    def _by_type(self, key: str) -> dict[int, float]:
        """Plot type code → the value of ``key`` its table gives (types without it left
        out)."""
        k = PLOT_TYPE_KEYS.index(key) + 1
        return {PLOT_TYPE_NAMES[e[0]]: e[k] for e in self.plot_types if e[k] is not None}

    def _per_plot(self, key: str, own: float | None, plot_type: np.ndarray | None
                  ) -> float | np.ndarray | None:
        by = self._by_type(key)
        if not by or plot_type is None:
            return own
        codes = np.asarray(plot_type)
        out = np.full(codes.shape, np.nan if own is None else float(own))
        for code, v in by.items():
            out[codes == code] = v
        return out

    def sigmas(self, plot_type: np.ndarray | None = None
               ) -> tuple[float | np.ndarray | None, float | np.ndarray | None]:
        """``(σr, σθ)`` of plots of types ``plot_type`` (codes of
        :data:`mhtrack.attributes.PLOT_TYPES`): the type's own where its table gives one,
        else the sensor's. Without type tables, or without ``plot_type``, the sensor's
        two scalars (today's values, unchanged)."""
        return (self._per_plot("sigma_range", self.sigma_range, plot_type),
                self._per_plot("sigma_bearing_deg", self.sigma_bearing_deg, plot_type))

    def pds(self, plot_type: np.ndarray | None = None) -> float | np.ndarray:
        """``P_D`` of plots of types ``plot_type``, as :meth:`sigmas` (the sensor's
        ``pd`` as a float when no type table gives one)."""
        return self._per_plot("pd", self.pd, plot_type)  # type: ignore[return-value]

    def _check_errors(self) -> None:
        """The error keys of the sensor's kind are present and in range; the other kind's
        are absent."""
        w = f"sensor {self.id}"
        if self.kind == "polar":
            limits = {"sigma_range": (MIN_SIGMA_M, MAX_SIGMA, "m"),
                      "sigma_bearing_deg": (MIN_SIGMA_BEARING_DEG, MAX_SIGMA_BEARING_DEG,
                                            "degrees")}
            other = ("sigma",)
        else:
            limits = {"sigma": (MIN_SIGMA_M, MAX_SIGMA, "m")}
            other = ("sigma_range", "sigma_bearing_deg")
            if self.kind == "adsb" and self.sigma is None:
                limits = {}  # each report's σ from its NACp/NUCp; ``sigma`` a fallback
        for key in other:
            if getattr(self, key) is not None:
                raise SensorFieldError(w, key, f"not used by a {self.kind} sensor")
        for key, (lo, hi, unit) in limits.items():
            v = getattr(self, key)
            if v is None:
                raise SensorFieldError(w, key, f"missing: required for a {self.kind} sensor")
            if not lo <= v <= hi:
                raise SensorFieldError(w, key, f"must be in [{short_number(lo)}, "
                                       f"{short_number(hi)}] {unit}, got {v:g}")

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
        self._check_distances()
        if self.reference is None:
            for i, s in enumerate(self.sensors):
                if s.kind == "polar" and s.position is not None:
                    raise SensorFieldError(
                        f"sensors[{i}]", "position",
                        "a polar sensor placed by position needs [origin] (or a sensor with "
                        "lat/lon) to put its range and bearing on the ellipsoid", index=i)

    def _check_distances(self) -> None:
        """Every lat/lon site within :data:`MAX_SITE_DISTANCE_M` of the frame's origin
        (geodesic distance on WGS-84); ``position`` sites are checked by the sensor."""
        ref = self.reference
        far = [(i, s) for i, s in enumerate(self.sensors) if s.lat is not None]
        if ref is None or not far:
            return
        from mhtrack.models.geodesy import inverse  # pyproj only when sites are given

        d, _ = inverse(ref[0], ref[1], [s.lat for _, s in far], [s.lon for _, s in far])
        for (i, s), di in zip(far, np.atleast_1d(d).tolist(), strict=True):
            if di > MAX_SITE_DISTANCE_M:
                what = ("[origin]" if self.origin is not None
                        else "the first site (the frame's origin)")
                raise SensorFieldError(
                    f"sensors[{i}]", "lat", f"site ({s.lat:g}, {s.lon:g}) is "
                    f"{di / 1e3:.0f} km from {what} at ({ref[0]:g}, {ref[1]:g}), farther "
                    f"than {MAX_SITE_DISTANCE_M / 1e3:.0f} km: the local plane cannot hold "
                    "it (wrong origin or a sign error in lat/lon?)", index=i)

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
