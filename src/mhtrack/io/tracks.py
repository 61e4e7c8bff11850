"""Tracks files: ``scan, time, track_id, x, y, vx, vy, plot`` [, ``score``, ``tentative``] —
tracker output, one row per reported track and scan, in non-decreasing scan order. ``plot``
is the 0-based row of the plots file that the track used at that scan, empty (CSV) or null
(Parquet) on a miss; ``tentative`` is 1 on rows reported after their scan, when the track
was confirmed later (the history output), else 0. See ``docs/file-formats.md``."""

from __future__ import annotations

import numpy as np

from mhtrack.errors import InputError
from mhtrack.io._checks import check_scan_order, check_unique, num
from mhtrack.io._frame import FLOAT, INT, float_array, int_array, read_frame, write_frame
from mhtrack.io._source import PathArg
from mhtrack.io.truth import read_truth
from mhtrack.records import NO_PLOT, TrackTable, TruthTable

REQUIRED = ("scan", "time", "track_id", "x", "y", "vx", "vy", "plot")
COLUMNS = dict.fromkeys((*REQUIRED, "score"), FLOAT) | {
    "scan": INT, "track_id": INT, "plot": INT, "tentative": INT}


def tracks_from_truth(truth: TruthTable) -> TrackTable:
    """The perfect tracker's output: each target a track (``track_id = target_id``), with
    no plot reference (``plot = -1``)."""
    return TrackTable(
        scan=truth.scan, time=truth.time, track_id=truth.target_id, x=truth.x, y=truth.y,
        vx=truth.vx, vy=truth.vy, plot=np.full(len(truth), NO_PLOT, np.int64),
    )


def read_tracks(path: PathArg, *, accept_truth: bool = True) -> TrackTable:
    """Read and validate a tracks file (``.csv`` or ``.parquet``).

    A file with a header and no rows is valid (the tracker reported nothing). Misses
    (empty / null ``plot``) become ``-1``; an explicit negative ``plot`` is an error.
    The covariance ``P`` is not stored in files and is ``None``.

    With ``accept_truth`` (default), a valid *truth* file is also accepted and read as the
    perfect tracker's output (:func:`tracks_from_truth`), so that ``evaluate truth truth``
    checks the metrics' zero point.

    Raises
    ------
    InputError : on any problem with the file, naming file, line/row and column.
    """
    try:
        f = read_frame(path, COLUMNS, REQUIRED, "tracks")
    except InputError as tracks_error:
        if not accept_truth or tracks_error.line is not None or tracks_error.row is not None:
            raise
        try:
            truth = read_truth(path)
        except InputError:
            raise tracks_error from None
        return tracks_from_truth(truth)
    scan = f.ints("scan")
    time = f.floats("time")
    tid = f.ints("track_id")
    cols = {c: f.floats(c) for c in ("x", "y", "vx", "vy")}
    plot = f.ints("plot", nullable=True, fill=NO_PLOT)
    written = ~f.nulls("plot")
    miss = "leave the cell empty" if f.src.format == "csv" else "use null"
    f.check(
        written & (plot < 0),
        "plot",
        lambda r: f"plot index {num(plot[r])} is negative ({miss} for a miss)",
    )
    score = f.floats("score") if f.has("score") else None
    tentative = None
    if f.has("tentative"):
        flag = f.ints("tentative")
        f.check((flag != 0) & (flag != 1), "tentative",
                lambda r: f"tentative must be 0 or 1, got {num(flag[r])}")
        tentative = flag == 1
    check_scan_order(f, scan, time)
    check_unique(f, scan, tid, "track_id")
    return TrackTable(scan=scan, time=time, track_id=tid, plot=plot, score=score,
                      tentative=tentative, **cols)


def write_tracks(table: TrackTable, path: PathArg) -> None:
    """Write ``table`` to a ``.csv`` or ``.parquet`` file; ``plot = -1`` (a miss) is
    written as an empty cell / null, and ``P`` is not stored."""
    cols = {
        "scan": int_array(table.scan),
        "time": float_array(table.time),
        "track_id": int_array(table.track_id),
        "x": float_array(table.x),
        "y": float_array(table.y),
        "vx": float_array(table.vx),
        "vy": float_array(table.vy),
        "plot": int_array(table.plot, missing=table.plot == NO_PLOT),
    }
    if table.score is not None:
        cols["score"] = float_array(table.score)
    if table.tentative is not None:
        cols["tentative"] = int_array(table.tentative.astype(np.int64))
    write_frame(path, cols)
