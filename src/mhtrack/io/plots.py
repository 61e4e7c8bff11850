"""Plots files: ``scan, time, sensor, x, y`` [, ``range, bearing``] [, ``origin``] — scans
— or, without ``scan``, timed plots (:mod:`mhtrack.io.timed_plots`).

One row per plot; the row order is the plot numbering that tracks files refer to
(0-based). See ``docs/file-formats.md``.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pyarrow as pa

from mhtrack.io._checks import check_scan_order, num
from mhtrack.io._frame import (
    FLOAT,
    INT,
    Frame,
    column_names,
    float_array,
    int_array,
    read_frame,
    write_frame,
)
from mhtrack.io._source import PathArg, Source
from mhtrack.io.plot_attributes import KINDS as ATTRIBUTE_KINDS
from mhtrack.io.plot_attributes import attribute_columns, read_attributes
from mhtrack.io.reorder import DEFAULT_REORDER_WINDOW_S
from mhtrack.io.timed_plots import read_timed_plots
from mhtrack.models.linalg2 import det2
from mhtrack.models.radars import SensorSet
from mhtrack.models.sensors import CartesianSensor, PolarRadar
from mhtrack.records import MAX_COORDINATE, NO_PLOT, PlotTable

REQUIRED = ("scan", "time", "sensor", "x", "y")
COLUMNS = {
    "scan": INT,
    "time": FLOAT,
    "sensor": INT,
    "x": FLOAT,
    "y": FLOAT,
    "range": FLOAT,
    "bearing": FLOAT,
    "origin": INT,
    **ATTRIBUTE_KINDS,
}

SensorRegistry = Mapping[int, CartesianSensor | PolarRadar]

#: Empty scans (scan numbers with no plot) that a plots file may imply between two of its
#: scans: at most MAX_GAP in one gap, and at most max(MAX_GAP, MAX_EMPTY_RATIO × the number
#: of scans with plots) in all; ``PlotTable.scans()`` feeds every one of them to the tracker.
MAX_GAP = 10_000
MAX_EMPTY_RATIO = 10


def is_timed(path: PathArg) -> bool:
    """The plots file has no ``scan`` column: timed plots (located errors if unreadable)."""
    return "scan" not in column_names(path)


def read_plots(
    path: PathArg, sensors: SensorSet | SensorRegistry | None = None, *,
    reorder_window_s: float = DEFAULT_REORDER_WINDOW_S,
) -> PlotTable:
    """Read and validate a plots file (``.csv`` or ``.parquet``).

    A file without a ``scan`` column holds timed plots and is read by
    :func:`~mhtrack.io.timed_plots.read_timed_plots` with ``sensors`` (a
    :class:`~mhtrack.models.radars.SensorSet`, from a sensors file) and
    ``reorder_window_s``. A file with ``scan`` is read as below (scans).

    Parameters
    ----------
    path : the file; its extension chooses the format.
    sensors : optional registry ``sensor id -> CartesianSensor | PolarRadar``. When given,
        every row's sensor must be in it; ``range``/``bearing`` may be empty (NaN) on the
        rows of Cartesian sensors; and the per-plot covariance ``R`` is computed — by
        ``PolarRadar.convert`` for polar rows, ``CartesianSensor.R`` for the others —
        unless every row comes from Cartesian sensors sharing one σ (then ``R`` is
        ``None`` and the tracker's own ``R = σ² I`` applies, as in the simulator).

    Returns
    -------
    PlotTable with ``x, y`` as written in the file; ``scan_times`` is left ``None`` (scans
    with no plot are filled in by :meth:`PlotTable.all_scan_times`).

    Raises
    ------
    InputError : on any problem with the file, naming file, line/row and column.
    """
    names = column_names(path)
    if "scan" not in names and {"time", "sensor"} <= set(names):
        if sensors is not None and not isinstance(sensors, SensorSet):
            raise TypeError("a plots file without 'scan' (timed plots) is read with a "
                            "SensorSet (a sensors file), not a sensor registry")
        return read_timed_plots(path, sensors, reorder_window_s=reorder_window_s)
    if isinstance(sensors, SensorSet):
        raise Source(path).error(
            "scans are read with a scenario's sensors (--scenario); a sensors file is for "
            "timed plots (one time per plot, no 'scan' column)", column="scan")
    f = read_frame(path, COLUMNS, REQUIRED, "plots")
    if f.n == 0:
        f.fail("no rows (a plots file needs at least one plot)")
    scan = f.ints("scan")
    time = f.floats("time")
    sensor = f.ints("sensor")
    x = f.floats("x")
    y = f.floats("y")
    for name, v in (("x", x), ("y", y)):
        f.check(np.abs(v) > MAX_COORDINATE, name,
                lambda r, v=v: f"{num(v[r])} m is beyond ±{MAX_COORDINATE:g} m of the "
                "frame's origin (a unit or parsing error?)")
    check_scan_order(f, scan, time)
    _check_gaps(f, scan)
    origin = None
    if f.has("origin"):
        origin = f.ints("origin")
        f.check(
            origin < -1,
            "origin",
            lambda r: f"origin {num(origin[r])} is invalid (a target id >= 0, or -1 for clutter)",
        )
    polar = np.zeros(len(scan), bool)
    if sensors is not None:
        polar = _check_sensors(f, sensor, sensors)
    rng, bearing = _range_bearing(f, sensor, polar, cartesian_may_be_empty=sensors is not None)
    R = None
    if sensors is not None and _needs_covariances(sensor, sensors):
        R = _covariances(sensor, rng, bearing, sensors)
        f.check(
            ~np.isfinite(R).all(axis=(1, 2)),
            "range",
            lambda r: f"range {num(rng[r])} is too large (its covariance overflows)",
        )
        # the tracker's own check (mhtrack.mht.validate), here where the file is known
        f.check(
            ~((R[:, 0, 0] > 0) & (det2(R) > 0)),
            "range",
            lambda r: f"range {num(rng[r])} and bearing {num(bearing[r])} give a covariance "
            f"{R[r].tolist()} that is not positive definite (sensor {num(sensor[r])}'s "
            "errors are too small for float64)",
        )
    return PlotTable(
        scan=scan, time=time, sensor=sensor, x=x, y=y,
        range=rng, bearing=bearing, origin=origin, R=R,
        attrs=read_attributes(f, polar=None if rng is None else (rng, bearing)),
    )  # fmt: skip


def _check_gaps(f: Frame, scan: np.ndarray) -> None:
    """Refuse scan-number gaps that would make the tracker run through a huge number of
    empty scans (see :data:`MAX_GAP`)."""
    new = np.flatnonzero(scan[1:] != scan[:-1]) + 1  # first row of each scan but the first
    if new.size == 0:
        return
    gap = scan[new].astype(np.float64) - scan[new - 1].astype(np.float64) - 1.0  # no overflow
    where = f.src.where

    def text(i: int) -> str:
        r = int(new[i])
        a, b = int(scan[r - 1]), int(scan[r])
        return (
            f"scan {b} follows scan {a} ({where(r - 1)}): the {b - a - 1} scan numbers "
            f"between them would each be tracked as an empty scan"
        )

    big = np.flatnonzero(gap > MAX_GAP)
    if big.size:
        i = int(big[0])
        f.fail(f"{text(i)}, more than the {MAX_GAP} allowed in one gap; renumber the scans",
               row=int(new[i]), column="scan")
    total = float(gap.sum())
    limit = max(MAX_GAP, MAX_EMPTY_RATIO * (new.size + 1))
    if total > limit:
        i = int(np.argmax(gap))
        f.fail(
            f"the file has {new.size + 1} scans with plots but {int(total)} scan numbers "
            f"without any, more than the {limit} allowed (max({MAX_GAP}, "
            f"{MAX_EMPTY_RATIO} × scans with plots)); the largest gap: {text(i)}; renumber "
            "the scans", row=int(new[i]), column="scan")


def _check_sensors(f: Frame, sensor: np.ndarray, sensors: SensorRegistry) -> np.ndarray:
    """Unknown sensor ids are an error; returns the mask of polar-sensor rows."""
    for key, s in sensors.items():
        if not isinstance(s, CartesianSensor | PolarRadar):
            raise TypeError(f"sensor registry entry {key!r} is {type(s).__name__}, not a sensor")
    known = np.fromiter(sensors.keys(), np.int64, len(sensors))
    listed = ", ".join(str(k) for k in sorted(sensors)) or "none"
    f.check(
        ~np.isin(sensor, known),
        "sensor",
        lambda r: f"unknown sensor {num(sensor[r])} (known sensors: {listed})",
    )
    polar_ids = np.array([k for k, s in sensors.items() if isinstance(s, PolarRadar)], np.int64)
    return np.isin(sensor, polar_ids)


def _range_bearing(
    f: Frame, sensor: np.ndarray, polar: np.ndarray, *, cartesian_may_be_empty: bool
) -> tuple[np.ndarray | None, np.ndarray | None]:
    have = [c for c in ("range", "bearing") if f.has(c)]
    if len(have) == 1:
        other = "bearing" if have[0] == "range" else "range"
        f.fail(f"column {have[0]!r} is present without column {other!r}; give both or neither")
    if not have:
        if polar.any():
            ids = ", ".join(str(i) for i in np.unique(sensor[polar]))
            f.fail(f"missing column(s) 'range', 'bearing', needed by polar sensor(s) {ids}")
        return None, None
    out = []
    for name in ("range", "bearing"):
        v = f.floats(name, nullable=True, finite=False)
        nulls = f.nulls(name)
        # Rows that must hold a measurement: all of them, unless the registry says Cartesian.
        must = polar if cartesian_may_be_empty else np.ones(v.size, bool)
        f.check(must & nulls, name, lambda r: _missing(sensor, polar, r))
        bad = ~np.isfinite(v) & ~nulls & (must | ~np.isnan(v))  # NaN ok where not needed
        f.check(bad, name, lambda r, name=name: f"value {f.text(name, r)!r} is not finite")
        out.append(v)
    rng, bearing = out
    f.check(rng < 0, "range", lambda r: f"range {num(rng[r])} is negative")
    return rng, bearing


def _missing(sensor: np.ndarray, polar: np.ndarray, r: int) -> str:
    if polar[r]:
        return f"value is missing (sensor {num(sensor[r])} is a polar radar)"
    return (
        "value is missing (range and bearing may be empty only on rows of Cartesian "
        "sensors, when a sensor registry is given)"
    )


def _needs_covariances(sensor: np.ndarray, sensors: SensorRegistry) -> bool:
    """Per-plot ``R`` unless every row is from a Cartesian sensor and they share one σ (then
    the tracker's own ``R = σ² I`` applies) — the simulator's rule."""
    used = [sensors[i] for i in np.unique(sensor).tolist()]
    if any(isinstance(s, PolarRadar) for s in used):
        return True
    return len({s.sigma for s in used if isinstance(s, CartesianSensor)}) > 1


def _covariances(
    sensor: np.ndarray, rng: np.ndarray, bearing: np.ndarray, sensors: SensorRegistry
) -> np.ndarray:
    R = np.empty((sensor.size, 2, 2))
    for sid in np.unique(sensor).tolist():
        rows = sensor == sid
        s = sensors[sid]
        if isinstance(s, PolarRadar):
            with np.errstate(over="ignore", invalid="ignore"):  # absurd ranges: checked after
                R[rows] = s.convert(np.column_stack((rng[rows], bearing[rows]))).R
        else:
            R[rows] = s.R
    return R


def check_scan_times(
    path: PathArg, table: PlotTable, scans: np.ndarray, times: np.ndarray, origin: str,
    *, rtol: float = 1e-6,
) -> None:
    """Check the plots read from ``path`` against the scan list of ``origin`` (e.g. a
    scenario file): every row's scan must be one of ``scans`` and its time the matching
    entry of ``times`` (to ``rtol``, relative). Raises a located :class:`InputError` for the
    first offending row."""
    src = Source(path)
    scans = np.asarray(scans, np.int64)
    times = np.asarray(times, np.float64)
    order = np.argsort(scans, kind="stable")
    scans, times = scans[order], times[order]
    if scans.size == 0:
        raise src.error(f"{origin} has no scans")
    pos = np.clip(np.searchsorted(scans, table.scan), 0, scans.size - 1)
    outside = np.flatnonzero(scans[pos] != table.scan)
    if outside.size:
        r = int(outside[0])
        raise src.error(
            f"scan {num(table.scan[r])} is not a scan of {origin} (scans "
            f"{num(scans[0])} to {num(scans[-1])}); {outside.size} row(s) are outside it",
            row=r, column="scan",
        )
    expected = times[pos]
    tol = rtol * np.maximum(np.abs(expected), np.abs(table.time)) + 1e-12
    off = np.flatnonzero(np.abs(table.time - expected) > tol)
    if off.size:
        r = int(off[0])
        raise src.error(
            f"scan {num(table.scan[r])} has time {num(table.time[r])} s, but {origin} gives "
            f"{num(expected[r])} s for it; the plots' times must match the scenario's k·T",
            row=r, column="time",
        )


def file_rows(table: PlotTable) -> np.ndarray | None:
    """The file row (0-based) of each row of ``table``, as :func:`write_plots` writes it
    (and as a timed file read it): ``table.file_row``; else, for a timed table, the rank
    of each row in time order (ties: table order); ``None`` when it is the table order."""
    if table.file_row is not None:
        return table.file_row
    if not table.timed:
        return None
    n = len(table)
    rank = np.empty(n, np.int64)
    rank[np.lexsort((np.arange(n), table.time))] = np.arange(n)
    return rank


def plots_to_file_rows(plot: np.ndarray, table: PlotTable) -> np.ndarray:
    """Table rows (``Scan.rows``, a track's ``plot``; ``-1`` kept) as file rows."""
    rows = file_rows(table)
    plot = np.asarray(plot, np.int64)
    if rows is None:
        return plot
    return np.where(plot == NO_PLOT, NO_PLOT, rows[np.maximum(plot, 0)])


#: :func:`plots_to_table_rows` of a file row the table does not hold (beyond the file, or
#: a row dropped as too late by the re-order rule, :mod:`mhtrack.io.reorder`).
NOT_A_ROW = -2


def plots_to_table_rows(plot: np.ndarray, table: PlotTable) -> np.ndarray:
    """The inverse of :func:`plots_to_file_rows`: file rows (``-1`` kept) as table rows;
    :data:`NOT_A_ROW` for a file row that is no row of ``table``."""
    rows = file_rows(table)
    plot = np.asarray(plot, np.int64)
    if rows is None:
        return np.where((plot >= len(table)) | (plot < NO_PLOT), NOT_A_ROW, plot)
    size = max(len(rows), int(rows.max()) + 1 if len(rows) else 0)
    inverse = np.full(size + 1, NOT_A_ROW, np.int64)  # the last: every row beyond
    inverse[rows] = np.arange(len(rows))
    at = np.where((plot < 0) | (plot > size), size, plot)
    return np.where(plot == NO_PLOT, NO_PLOT, inverse[at])


def write_plots(table: PlotTable, path: PathArg) -> None:
    """Write ``table`` to a ``.csv`` or ``.parquet`` file (``R`` and ``scan_times`` are not
    stored; NaN ``range``/``bearing`` are written as empty cells / nulls; the plots'
    attributes, when any, as :mod:`~mhtrack.io.plot_attributes` columns after them).

    A timed table (``table.timed``) is written without ``scan`` — ``time, sensor`` [,
    ``range, bearing``], ``x, y`` (left out when every plot is polar: the reader converts
    range and bearing with the sensors file) [, ``origin``] — its rows in file order
    (:func:`file_rows`: as read, or by time), which :func:`read_plots` sorts back into
    the same table."""
    if (table.range is None) != (table.bearing is None):
        raise ValueError("PlotTable has only one of range/bearing; both or neither are needed")
    rows = file_rows(table)
    order = slice(None) if rows is None else np.argsort(rows, kind="stable")
    cols: dict[str, pa.Array] = {} if table.timed else {"scan": int_array(table.scan)}
    cols["time"] = float_array(table.time[order])
    cols["sensor"] = int_array(table.sensor[order])
    if table.timed and table.range is not None and table.bearing is not None:
        cols["range"] = float_array(table.range[order], nan_as_null=True)
        cols["bearing"] = float_array(table.bearing[order], nan_as_null=True)
    polar = table.range is not None and bool(np.isfinite(table.range).all())
    if not (table.timed and polar):  # timed polar plots: x, y follow from range, bearing
        cols["x"] = float_array(table.x[order])
        cols["y"] = float_array(table.y[order])
    if not table.timed and table.range is not None and table.bearing is not None:
        cols["range"] = float_array(table.range, nan_as_null=True)
        cols["bearing"] = float_array(table.bearing, nan_as_null=True)
    if table.origin is not None:
        cols["origin"] = int_array(table.origin[order])
    if table.attrs is not None:
        cols.update(attribute_columns(table.attrs, order))
    write_frame(path, cols)
