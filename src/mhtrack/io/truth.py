"""Truth files: ``scan, time, target_id, x, y, vx, vy`` — one row per live target and scan,
in non-decreasing scan order and, within a scan, increasing target id (the order of
:class:`~mhtrack.records.TruthTable`) — with ``lat, lon`` and east/north ``vx, vy`` when
written with a frame (:mod:`mhtrack.io._geodetic`). See ``docs/file-formats.md``."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from mhtrack.io import _geodetic
from mhtrack.io._checks import check_scan_order, check_unique, num
from mhtrack.io._frame import (
    FLOAT,
    INT,
    column_names,
    float_array,
    read_frame,
    write_frame,
)
from mhtrack.io._source import PathArg
from mhtrack.records import TruthTable

if TYPE_CHECKING:
    from mhtrack.models.geodesy import LocalFrame

REQUIRED = ("scan", "time", "target_id", "x", "y", "vx", "vy")
COLUMNS = dict.fromkeys(REQUIRED, FLOAT) | {"scan": INT, "target_id": INT} | _geodetic.COLUMNS


def read_truth(path: PathArg, *, frame: LocalFrame | None = None) -> TruthTable:
    """Read and validate a truth file (``.csv`` or ``.parquet``).

    A file with a header and no rows is valid (a scenario with no target) and gives an
    empty table. A file with ``lat, lon`` has east/north ``vx, vy``; the local state
    comes from ``x, y, vx_grid, vy_grid``, or from converting with ``frame``
    (:func:`mhtrack.io._geodetic.read_state`).

    Raises
    ------
    InputError : on any problem with the file, naming file, line/row and column.
    """
    f = read_frame(path, COLUMNS, _geodetic.required(column_names(path), REQUIRED), "truth")
    scan = f.ints("scan")
    time = f.floats("time")
    tid = f.ints("target_id")
    f.check(tid < 0, "target_id", lambda r: f"target_id {num(tid[r])} is negative")
    cols = _geodetic.read_state(f, frame)
    check_scan_order(f, scan, time)
    check_unique(f, scan, tid, "target_id")
    same = np.concatenate(([False], scan[1:] == scan[:-1]))
    back = np.concatenate(([False], tid[1:] < tid[:-1]))
    f.check(
        same & back,
        "target_id",
        lambda r: (
            f"target_id {num(tid[r])} after {num(tid[r - 1])} in scan {num(scan[r])}; "
            "rows of a scan must be in increasing target_id order"
        ),
    )
    return TruthTable(scan=scan, time=time, target_id=tid, **cols)


def write_truth(table: TruthTable, path: PathArg, frame: LocalFrame | None = None) -> None:
    """Write ``table`` to a ``.csv`` or ``.parquet`` file; with ``frame``, also ``lat, lon``
    and east/north ``vx, vy`` (:func:`mhtrack.io._geodetic.state_columns`)."""
    write_frame(path, _geodetic.row_columns(
        ("scan", table.scan), float_array(table.time), ("target_id", table.target_id),
        (table.x, table.y, table.vx, table.vy), frame))
