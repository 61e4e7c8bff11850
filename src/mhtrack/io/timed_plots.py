"""Timed plots files (no ``scan`` column): each plot with its own ``time`` and ``sensor``,
and its position as ``range, bearing`` (polar radars), ``x, y`` (local frame) or
``lat, lon`` (WGS-84) — real data from several rotating radars (docs/file-formats.md,
"Timed plots").

Reading converts every plot into the local frame with :mod:`mhtrack.models.geodesy`
through the :class:`~mhtrack.models.radars.SensorSet` of a sensors file (its frame and
sites), keeps the rows that the sources' re-order buffer keeps (:mod:`mhtrack.io.reorder`:
rows out of order within the window sorted, later ones dropped with one warning), cuts them into
one-sensor frames with :func:`mhtrack.frames.make_frames` and returns a timed
:class:`~mhtrack.records.PlotTable` whose ``file_row`` maps each row back to the file.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from mhtrack.attributes import PlotAttributes
from mhtrack.frames import frame_lengths, make_frames
from mhtrack.io._checks import num
from mhtrack.io._frame import FLOAT, INT, TIME, Frame, read_frame
from mhtrack.io._source import PathArg
from mhtrack.io._times import is_iso, seconds
from mhtrack.io.plot_attributes import KINDS as ATTRIBUTE_KINDS
from mhtrack.io.plot_attributes import read_attributes
from mhtrack.io.reorder import DEFAULT_REORDER_WINDOW_S, kept_and_late
from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.records import MAX_COORDINATE, PlotTable

#: Largest range accepted (m): 20 000 km, about half a meridian (20 003.9 km) — farther
#: than any point of the Earth from the site along the ground.
MAX_RANGE_M = 2e7

REQUIRED = ("time", "sensor")
COLUMNS = {"time": TIME, "sensor": INT, "range": FLOAT, "bearing": FLOAT, "x": FLOAT,
           "y": FLOAT, "lat": FLOAT, "lon": FLOAT, "sigma": FLOAT, "origin": INT,
           **ATTRIBUTE_KINDS}
#: Position column pairs, in the order a row's position is taken from them.
PAIRS = (("range", "bearing"), ("x", "y"), ("lat", "lon"))
_NEEDS_SENSORS = "read them with a sensors file (mhtrack track --sensors FILE)"


def read_timed_plots(
    path: PathArg, sensors: SensorSet | None = None, *,
    reorder_window_s: float = DEFAULT_REORDER_WINDOW_S,
) -> PlotTable:
    """Read a plots file without ``scan`` (docs/file-formats.md, "Timed plots").

    Without ``sensors`` every row needs ``x, y`` (``R`` is then ``None``: the tracker's
    own σ applies) and ``range``/``bearing`` are only carried along. With ``sensors``:
    a polar sensor's rows need ``range, bearing`` (``z, R`` by
    :func:`~mhtrack.models.geodesy.polar_to_local`), a Cartesian sensor's rows ``x, y`` or
    ``lat, lon`` (``LocalFrame.to_local``) with ``R = σ² I``. Rows out of time order are
    kept or dropped by the one rule of the sources (:mod:`mhtrack.io.reorder`, window
    ``reorder_window_s``): a dropped row is left out with one warning line naming the
    first one's line, as ``track`` says it.

    Returns a ``PlotTable(timed=True)`` sorted by frame, then time; ``file_row[i]`` is the
    0-based file row of table row ``i``.
    """
    if not reorder_window_s >= 0:
        raise ValueError(f"reorder_window_s must be >= 0, got {reorder_window_s!r}")
    f, c = read_timed_columns(path, sensors)
    on_time, late = kept_and_late(c.time, reorder_window_s)
    rows = np.flatnonzero(on_time)
    time, sensor = c.time, c.sensor
    if late.n:
        logging.getLogger("mhtrack").warning("%s", late.line(
            str(path), f.src.where(int(late.first["row"]))))  # type: ignore[call-overload]
        time, sensor = time[rows], sensor[rows]
    periods = {s: sensors.sensor(s).period if sensors is not None else None
               for s in np.unique(sensor).tolist()}
    frame, order = make_frames(time, sensor, frame_lengths(periods))
    idx = rows[order]  # file rows in table order: each column is copied once, by them

    def take(v: np.ndarray | None) -> np.ndarray | None:
        return None if v is None else v[idx]

    return PlotTable(
        scan=frame[order], time=c.time[idx], sensor=c.sensor[idx], x=take(c.x),
        y=take(c.y), range=take(c.range), bearing=take(c.bearing), origin=take(c.origin),
        R=take(c.R), timed=True, file_row=idx.astype(np.int64), iso_times=is_iso(f),
        attrs=None if c.attrs is None else c.attrs.take(idx),
    )  # type: ignore[arg-type]


@dataclass(frozen=True)
class TimedColumns:
    """The validated rows of a timed plots file, in file order, positions in the local
    frame (``R`` ``None`` without a sensors file)."""

    time: np.ndarray
    sensor: np.ndarray
    x: np.ndarray
    y: np.ndarray
    range: np.ndarray | None
    bearing: np.ndarray | None
    origin: np.ndarray | None
    R: np.ndarray | None
    attrs: PlotAttributes | None = None


def read_timed_columns(path: PathArg, sensors: SensorSet | None = None
                       ) -> tuple[Frame, TimedColumns]:
    """Read, check and convert a timed plots file (as :func:`read_timed_plots`, without
    re-ordering or cutting frames): the file (for located errors) and its rows in file
    order."""
    f = read_frame(path, COLUMNS, REQUIRED, "timed plots")
    if f.n == 0:
        f.fail("no rows (a plots file needs at least one plot)")
    _check_pairs(f)
    time = seconds(f)
    sensor = f.ints("sensor")
    origin = None
    if f.has("origin"):
        origin = f.ints("origin")
        f.check(origin < -1, "origin", lambda r: f"origin {num(origin[r])} is invalid (a "
                "target id >= 0, or -1 for clutter)")
    rng, bearing = _range_bearing(f)
    lat, lon = _lat_lon(f)
    attrs = read_attributes(f, polar=None if rng is None else (rng, bearing),
                            site=None if sensors is None else _sites(sensor, sensors))
    if sensors is None:
        x, y, R = _without_sensors(f)
    else:
        x, y, R = _convert(f, sensor, rng, bearing, lat, lon, sensors,
                           None if attrs is None else attrs.plot_type)
    for name, v in (("x", x), ("y", y)):
        f.check(np.abs(v) > MAX_COORDINATE, name if f.has(name) else None,
                lambda r, v=v, name=name: f"{name} = {num(v[r])} m is beyond "
                f"±{MAX_COORDINATE:g} m of the frame's origin (a unit or parsing error?)")
    return f, TimedColumns(time, sensor, x, y, rng, bearing, origin, R, attrs)


def polar_plots(sensors: SensorSet, sensor_id: int, rng: np.ndarray, bearing: np.ndarray,
                plot_type: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``x, y, R`` in the sensors' local frame of polar radar ``sensor_id``'s plots at
    ground ``rng`` (m) and ``bearing`` (deg), by
    :func:`~mhtrack.models.geodesy.polar_to_local` with the radar's σ — per plot the σ of
    its type (``plot_type``, codes of :data:`mhtrack.attributes.PLOT_TYPES`) where the
    sensors file gives that type its own (:meth:`RadarSensor.sigmas`). Element-wise: a
    plot's result does not depend on the others (the sources convert chunk by chunk)."""
    from mhtrack.models.geodesy import polar_to_local  # pyproj only when converting

    s = sensors.sensor(sensor_id)
    sr, sb = s.sigmas(plot_type)
    z, R = polar_to_local(sensors.frame(), *sensors.site_latlon(sensor_id), rng, bearing,
                          sr, sb)
    return z[:, 0], z[:, 1], R


def _check_pairs(f: Frame) -> None:
    """Position columns come in pairs, and at least one pair is there."""
    for a, b in PAIRS:
        if f.has(a) != f.has(b):
            have, other = (a, b) if f.has(a) else (b, a)
            f.fail(f"column {have!r} is present without column {other!r}; give both or "
                   "neither")
    if not any(f.has(a) for a, _ in PAIRS):
        f.fail("no plot positions: a plots file without 'scan' needs columns 'range' and "
               "'bearing', 'x' and 'y', or 'lat' and 'lon'")


def _floats_or_none(f: Frame, name: str) -> np.ndarray | None:
    """A position column that may be empty on some rows (NaN there), finite elsewhere."""
    if not f.has(name):
        return None
    v = f.floats(name, nullable=True, finite=False)
    nulls = f.nulls(name)
    f.check(~np.isfinite(v) & ~nulls, name, lambda r: f"value {f.text(name, r)!r} is not "
            "finite")
    return v


def _range_bearing(f: Frame) -> tuple[np.ndarray | None, np.ndarray | None]:
    """``range`` (≥ 0 m) and ``bearing`` (in [0, 360]°), NaN where empty, or ``None``."""
    rng, bearing = _floats_or_none(f, "range"), _floats_or_none(f, "bearing")
    if rng is None or bearing is None:
        return None, None
    f.check(rng < 0, "range", lambda r: f"range {num(rng[r])} m is negative")
    f.check(rng > MAX_RANGE_M, "range", lambda r: f"range {num(rng[r])} m is beyond "
            f"{MAX_RANGE_M / 1e3:.0f} km, half-way round the Earth (a unit error?)")
    f.check((bearing < 0) | (bearing > 360), "bearing", lambda r: f"bearing "
            f"{num(bearing[r])} is outside [0, 360] degrees (clockwise from north)")
    for name, a, b in (("bearing", rng, bearing), ("range", bearing, rng)):
        f.check(~np.isnan(a) & np.isnan(b), name, lambda r: "value is missing (range and "
                "bearing come together)")
    return rng, bearing


def _sites(sensor: np.ndarray, sensors: SensorSet) -> tuple[np.ndarray, np.ndarray]:
    """Each row's site latitude (°) and altitude (m; NaN where not given, or no site)."""
    lat, alt = np.full(sensor.size, np.nan), np.full(sensor.size, np.nan)
    for s in sensors.sensors:
        rows = sensor == s.id
        if s.has_site and rows.any():
            lat[rows] = sensors.site_latlon(s.id)[0]
            alt[rows] = np.nan if s.alt is None else s.alt
    return lat, alt


def _lat_lon(f: Frame) -> tuple[np.ndarray | None, np.ndarray | None]:
    """``lat`` in [−90, 90]° and ``lon`` in [−180, 180]° (NaN where empty), or ``None``."""
    lat, lon = _floats_or_none(f, "lat"), _floats_or_none(f, "lon")
    if lat is None or lon is None:
        return None, None
    f.check(np.abs(lat) > 90, "lat", lambda r: f"latitude {num(lat[r])} is outside "
            "[-90, 90] degrees")
    f.check(np.abs(lon) > 180, "lon", lambda r: f"longitude {num(lon[r])} is outside "
            "[-180, 180] degrees")
    for name, a, b in (("lon", lat, lon), ("lat", lon, lat)):
        f.check(~np.isnan(a) & np.isnan(b), name, lambda r: "value is missing (lat and "
                "lon come together)")
    return lat, lon


def _without_sensors(f: Frame) -> tuple[np.ndarray, np.ndarray, None]:
    if not f.has("x"):
        what = "range/bearing" if f.has("range") else "lat/lon"
        needs = "the radar sites" if f.has("range") else "the local frame's origin"
        f.fail(f"{what} plots need {needs}: {_NEEDS_SENSORS}")
    return f.floats("x"), f.floats("y"), None


def _convert(
    f: Frame, sensor: np.ndarray, rng: np.ndarray | None, bearing: np.ndarray | None,
    lat: np.ndarray | None, lon: np.ndarray | None, sensors: SensorSet,
    plot_type: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions and covariances of every row in the sensors' local frame (a polar
    radar's plots with the σ of their ``plot_type`` where the sensors file gives it)."""
    ids = sensors.ids
    listed = ", ".join(str(i) for i in ids)
    f.check(~np.isin(sensor, np.asarray(ids, np.int64)), "sensor", lambda r: (
        f"unknown sensor {num(sensor[r])} (the sensors file lists {listed})"))
    kinds = {s.id: s for s in sensors.sensors}
    polar = np.isin(sensor, [s.id for s in sensors.sensors if s.kind == "polar"])
    has_rb = np.zeros(f.n, bool) if rng is None else ~np.isnan(rng)
    if polar.any() and rng is None:
        used = ", ".join(str(i) for i in np.unique(sensor[polar]).tolist())
        f.fail(f"missing columns 'range', 'bearing', needed by polar sensor(s) {used}")
    f.check(polar & ~has_rb, "range", lambda r: f"value is missing (sensor "
            f"{num(sensor[r])} is a polar radar: its plots are range and bearing)")
    siteless = np.isin(sensor, [s.id for s in sensors.sensors
                                if s.kind == "polar" and not s.has_site])
    f.check(siteless, "sensor", lambda r: (
        f"sensor {num(sensor[r])} is a polar radar without a site in the sensors file: "
        "give its lat and lon (or position) to place its range/bearing plots (an ASTERIX "
        "recording takes it from the radar's CAT034 I034/120)"))

    def not_polar(r: int) -> str:
        s = kinds[int(sensor[r])]
        what = "a cartesian sensor" + ("" if s.has_site else " without a site")
        return (f"sensor {s.id} is {what}: a range/bearing plot needs a polar sensor with "
                "its site (lat/lon or position) in the sensors file")

    f.check(~polar & has_rb, "range", not_polar)
    x, y = np.full(f.n, np.nan), np.full(f.n, np.nan)
    R = np.zeros((f.n, 2, 2))
    for s in sensors.sensors:
        rows = np.flatnonzero(sensor == s.id)
        if rows.size == 0:
            continue
        if s.kind == "polar":
            x[rows], y[rows], R[rows] = polar_plots(
                sensors, s.id, rng[rows], bearing[rows],  # type: ignore[index]
                None if plot_type is None else plot_type[rows])
        else:
            x[rows], y[rows] = _cartesian(f, sensors, rows, s.id, lat, lon)
            R[rows] = np.eye(2) * _sigmas(f, s, rows)[:, None, None] ** 2
    return x, y, R


def _sigmas(f: Frame, s: RadarSensor, rows: np.ndarray) -> np.ndarray:
    """σ (m per axis) of a Cartesian or ADS-B sensor's rows: an ADS-B report's own
    ``sigma`` (the column ``mhtrack convert`` writes, from its NACp/NUCp) where given,
    else the sensor's ``sigma``; a row with neither is refused."""
    sig = np.full(rows.size, np.nan if s.sigma is None else float(s.sigma))
    own = _floats_or_none(f, "sigma") if s.kind == "adsb" else None
    if own is not None:
        mine = np.zeros(f.n, bool)
        mine[rows] = True
        f.check(mine & ~(own > 0) & ~np.isnan(own), "sigma", lambda r: (
            f"sigma {num(own[r])} m is not > 0"))  # type: ignore[index]
        sig = np.where(np.isnan(own[rows]), sig, own[rows])
    bad = np.zeros(f.n, bool)
    bad[rows] = np.isnan(sig)
    f.check(bad, "sigma" if own is not None else "sensor", lambda r: (
        f"no accuracy: sensor {s.id} is an ADS-B station without a sigma in the sensors "
        "file, and this report gives none (NACp/NUCp 0)"))
    return sig


def _cartesian(f: Frame, sensors: SensorSet, rows: np.ndarray, sensor_id: int,
               lat: np.ndarray | None, lon: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """A Cartesian sensor's rows: ``x, y`` where written, else ``lat, lon``."""
    n = rows.size
    x, y = _floats_or_none(f, "x"), _floats_or_none(f, "y")
    xr = np.full(n, np.nan) if x is None or y is None else x[rows]
    yr = np.full(n, np.nan) if x is None or y is None else y[rows]
    use_xy = ~np.isnan(xr) & ~np.isnan(yr)
    la = np.full(n, np.nan) if lat is None or lon is None else lat[rows]
    lo = np.full(n, np.nan) if lat is None or lon is None else lon[rows]
    use_ll = ~use_xy & ~np.isnan(la)
    none = np.zeros(f.n, bool)
    none[rows] = ~use_xy & ~use_ll
    f.check(none, "x" if x is not None else "lat", lambda r: (
        f"value is missing (sensor {sensor_id} is cartesian: give x and y, or lat and lon)"))
    if use_ll.any():
        try:
            frame = sensors.frame()
        except ValueError:
            f.fail("lat/lon plots need the local frame's origin: give [origin] (or a "
                   "sensor's lat/lon) in the sensors file", row=int(rows[use_ll][0]),
                   column="lat")
        xr[use_ll], yr[use_ll] = frame.to_local(la[use_ll], lo[use_ll])
    return xr, yr
