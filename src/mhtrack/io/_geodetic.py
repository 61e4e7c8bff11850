"""The state columns of truth and tracks files, in the local frame or geodetic.

Without a frame a file holds ``x, y, vx, vy``: position and velocity in the local
east-north plane (as today). With a :class:`~mhtrack.models.geodesy.LocalFrame` the
writers add the WGS-84 position and give the velocity east/north at the point::

    x, y, lat, lon, vx, vy, vx_grid, vy_grid

``lat, lon = frame.to_geodetic(x, y)``; ``vx, vy`` (east, north, m/s) ``=
frame.velocity_to_geodetic(x, y, vx_grid, vy_grid)``; ``vx_grid, vy_grid`` the velocity
in the local plane, exactly as held in memory. A file **with** ``lat, lon`` has east/north
``vx, vy``; the readers take the local state from ``x, y, vx_grid, vy_grid`` when present
(exact, no frame needed: what ``evaluate`` scores is what the tracker produced, bit for
bit), else convert ``lat, lon`` (``frame.to_local``) and east/north velocities
(``frame.velocity_to_local``) with the frame the caller gives (the sensors file's).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa

from mhtrack.io._checks import num
from mhtrack.io._frame import FLOAT, Frame, float_array, int_array

if TYPE_CHECKING:  # pyproj is imported only by whoever builds a frame
    from mhtrack.models.geodesy import LocalFrame

#: Columns the readers may find besides ``x, y, vx, vy``.
COLUMNS = dict.fromkeys(("lat", "lon", "vx_grid", "vy_grid"), FLOAT)


def is_geodetic(names: Sequence[str]) -> bool:
    """The file has ``lat, lon`` (then its ``vx, vy`` are east/north)."""
    return "lat" in names and "lon" in names


def required(names: Sequence[str], base: Sequence[str]) -> tuple[str, ...]:
    """``base`` (which lists ``x, y``), with ``lat, lon`` in place of ``x, y`` for a
    geodetic file without ``x, y``."""
    if is_geodetic(names) and not ("x" in names and "y" in names):
        return (*(c for c in base if c not in ("x", "y")), "lat", "lon")
    return tuple(base)


def state_columns(
    x: np.ndarray, y: np.ndarray, vx: np.ndarray, vy: np.ndarray, frame: LocalFrame | None
) -> dict[str, pa.Array]:
    """The columns to write for local-frame states (module docstring)."""
    if frame is None:
        return {"x": float_array(x), "y": float_array(y), "vx": float_array(vx),
                "vy": float_array(vy)}
    if len(x) == 0:
        lat = lon = ve = vn = np.zeros(0)
    else:
        lat, lon = frame.to_geodetic(x, y)
        ve, vn = frame.velocity_to_geodetic(x, y, vx, vy)
    return {"x": float_array(x), "y": float_array(y), "lat": float_array(lat),
            "lon": float_array(lon), "vx": float_array(ve), "vy": float_array(vn),
            "vx_grid": float_array(vx), "vy_grid": float_array(vy)}


def row_columns(key: tuple[str, np.ndarray], time: pa.Array, ident: tuple[str, np.ndarray],
                state: tuple[np.ndarray, ...], frame: LocalFrame | None) -> dict[str, pa.Array]:
    """The leading columns of a truth or tracks file, in order: ``key`` (``scan`` or
    ``frame``), ``time``, the id column ``ident`` (``target_id`` or ``track_id``), then the
    state ``x, y, vx, vy`` (:func:`state_columns`)."""
    return {key[0]: int_array(key[1]), "time": time, ident[0]: int_array(ident[1]),
            **state_columns(*state, frame)}


def read_state(f: Frame, frame: LocalFrame | None, *, geodetic: bool = False
               ) -> dict[str, np.ndarray]:
    """``x, y, vx, vy`` in the local frame from a file's columns (module docstring); with
    ``geodetic`` a file with ``lat, lon`` is converted with ``frame`` even when it has
    ``x, y`` (whose frame may be another: a reference system's tracks are placed in
    ``frame`` from WGS-84 too)."""
    if not (f.has("lat") and f.has("lon")):
        return {c: f.floats(c) for c in ("x", "y", "vx", "vy")}
    lat, lon = f.floats("lat"), f.floats("lon")
    f.check(np.abs(lat) > 90, "lat", lambda r: f"latitude {num(lat[r])} is outside "
            "[-90, 90] degrees")
    f.check(np.abs(lon) > 180, "lon", lambda r: f"longitude {num(lon[r])} is outside "
            "[-180, 180] degrees")
    ve, vn = f.floats("vx"), f.floats("vy")
    grid = f.has("vx_grid") and f.has("vy_grid") and not geodetic
    xy = f.has("x") and f.has("y") and not geodetic
    if not (grid and xy) and frame is None:
        missing = " and ".join(p for p, ok in (("x, y", xy), ("vx_grid, vy_grid", grid))
                               if not ok)
        f.fail(f"has lat, lon (so vx, vy are east/north) but no {missing}: read it with the "
               "sensors file, whose frame converts them to the local plane")
    if xy:
        x, y = f.floats("x"), f.floats("y")
    elif len(lat):
        x, y = frame.to_local(lat, lon)  # type: ignore[union-attr]
    else:
        x = y = np.zeros(0)
    if grid:
        vx, vy = f.floats("vx_grid"), f.floats("vy_grid")
    elif len(lat):
        vx, vy = frame.velocity_to_local(lat, lon, ve, vn)  # type: ignore[union-attr]
    else:
        vx = vy = np.zeros(0)
    return {"x": np.asarray(x, np.float64), "y": np.asarray(y, np.float64),
            "vx": np.asarray(vx, np.float64), "vy": np.asarray(vy, np.float64)}
