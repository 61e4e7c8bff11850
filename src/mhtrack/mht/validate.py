"""The scan check at the library boundary: every plot the tracker takes is finite, inside
the frame, with a unique row id and a valid covariance, and scans come in time order,
their times within ``±MAX_TIME_S`` (:mod:`mhtrack.bounds`).

Each problem raises :class:`~mhtrack.errors.InputError` (a ``ValueError``) naming the
scan, the plot's row id (for a plots file read by :mod:`mhtrack.io`, its 0-based data
row) and the field (``key``: ``time``, ``t``, ``z``, ``rows``, ``R``). A scan has no file:
the readers check what they read (file, line, column) before it gets here."""

from __future__ import annotations

import math

import numpy as np

from mhtrack.bounds import MAX_TIME_S
from mhtrack.errors import InputError
from mhtrack.models.linalg2 import det2
from mhtrack.records import MAX_COORDINATE, Scan


def validate_scan(
    scan: Scan, default_R: np.ndarray, last_time: float | None, last_index: int | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(z, R, rows)`` of ``scan``: positions (n, 2), covariances — ``default_R`` (2, 2)
    when the scan has none, else (n, 2, 2) with unset (all-NaN) ones replaced by it — and
    row ids (n,). Raises :class:`InputError` saying what is wrong and where."""
    z = np.asarray(scan.z, dtype=float).reshape(-1, 2)
    n = len(z)
    rows = np.asarray(scan.rows, dtype=np.int64).reshape(-1)
    if rows.size != n:
        raise InputError(f"scan {scan.index}: {rows.size} row ids for {n} plots", key="rows")
    if not math.isfinite(scan.time):
        raise InputError(f"scan {scan.index}: time {scan.time} is not finite", key="time")
    if abs(scan.time) > MAX_TIME_S:
        raise InputError(f"scan {scan.index}: time {scan.time:g} s is beyond "
                         f"±{MAX_TIME_S:g} s (mhtrack.bounds.MAX_TIME_S)", key="time")
    timed = scan.t is not None
    # frames of two radars may end at the same time; scans must move on
    if last_time is not None and not (scan.time >= last_time if timed
                                      else scan.time > last_time):
        raise InputError(
            f"scan {scan.index}: time {scan.time} s is not after the previous scan "
            f"({last_index}, {last_time} s); dt must be > 0", key="time"
        )
    if timed:
        t = np.asarray(scan.t, float).reshape(-1)
        if (t.size != n or not np.isfinite(t).all() or (t > scan.time).any()
                or (n and t.min() < -MAX_TIME_S)):
            raise InputError(f"scan {scan.index}: plot times must be {n} finite values "
                             f"within ±{MAX_TIME_S:g} s, <= the frame's time {scan.time} s",
                             key="t")
    if not (np.abs(z) <= MAX_COORDINATE).all():  # false for NaN and ±inf too
        _position_error(scan, z, rows)
    # row ids of a PlotTable's scan ascend: unique without sorting
    if n > 1 and not (rows[1:] > rows[:-1]).all() and np.unique(rows).size != n:
        raise InputError(f"scan {scan.index}: plot row ids are not unique", key="rows")
    if scan.R is None:
        return z, default_R, rows
    R = np.asarray(scan.R, dtype=float)
    if R.shape != (n, 2, 2):
        raise InputError(f"scan {scan.index}: R has shape {R.shape}, expected ({n}, 2, 2)",
                         key="R")
    finite = bool(np.isfinite(R).all())
    if not finite:
        unset = np.isnan(R).all(axis=(1, 2))  # PlotTable.from_scans: "use the tracker's R"
        if unset.any():
            R = R.copy()
            R[unset] = default_R
            finite = bool(np.isfinite(R).all())
    good = (R[:, 0, 0] > 0) & (det2(R) > 0)
    if not finite:
        good &= np.isfinite(R).all(axis=(1, 2))
    bad = ~good
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(
            f"scan {scan.index}: plot row {int(rows[i])} has an invalid covariance "
            f"{R[i].tolist()} (field 'R': R[0, 0] > 0 and det R > 0 are needed)",
            row=int(rows[i]), column="R", key="R")
    return z, R, rows


def _position_error(scan: Scan, z: np.ndarray, rows: np.ndarray) -> None:
    """Raise for the first plot of ``z`` (n, 2) with a non-finite position, else for the
    first beyond ``MAX_COORDINATE``."""
    bad = ~np.isfinite(z).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(
            f"scan {scan.index}: plot row {int(rows[i])} has a non-finite position "
            f"{z[i].tolist()} (field 'z')", row=int(rows[i]), column="z", key="z")
    i = int(np.flatnonzero(np.abs(z).max(axis=1) > MAX_COORDINATE)[0])
    raise InputError(
        f"scan {scan.index}: plot row {int(rows[i])} lies at {z[i].tolist()} m, "
        f"beyond ±{MAX_COORDINATE:g} m of the frame's origin (field 'z'; a unit or "
        "parsing error?)", row=int(rows[i]), column="z", key="z")
