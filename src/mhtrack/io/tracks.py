"""Tracks files: ``scan, time, track_id, x, y, vx, vy, plot`` [, ``score``, ``tentative``,
the attribute columns of :mod:`mhtrack.io.track_attributes`] —
tracker output, one row per reported track and scan, in non-decreasing scan order. ``plot``
is the 0-based row of the plots file that the track used at that scan, empty (CSV) or null
(Parquet) on a miss; ``tentative`` is 1 on rows reported after their scan, when the track
was confirmed later (the history output), else 0. Written with a frame, ``lat, lon`` and
east/north ``vx, vy`` (:mod:`mhtrack.io._geodetic`). See ``docs/file-formats.md``."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.attributes import TrackAttributes
from mhtrack.errors import InputError
from mhtrack.io import _geodetic
from mhtrack.io._checks import check_scan_order, check_unique, num
from mhtrack.io._frame import (
    FLOAT,
    INT,
    TIME,
    column_names,
    float_array,
    int_array,
    read_frame,
    write_frame,
)
from mhtrack.io._source import PathArg, file_format
from mhtrack.io._times import seconds, time_column
from mhtrack.io.plots import NOT_A_ROW, plots_to_file_rows, plots_to_table_rows
from mhtrack.io.track_attributes import (
    KINDS,
    read_track_attributes,
    track_attribute_columns,
)
from mhtrack.io.truth import read_truth
from mhtrack.records import NO_PLOT, PlotTable, TrackTable, TruthTable

if TYPE_CHECKING:
    import pyarrow as pa

    from mhtrack.models.geodesy import LocalFrame

REQUIRED = ("scan", "time", "track_id", "x", "y", "vx", "vy", "plot")
#: Tracks of timed plots (several rotating radars) number their rows by ``frame``
#: (:mod:`mhtrack.frames`) instead of ``scan``, and each row has its state's own time.
TIMED_REQUIRED = ("frame", *REQUIRED[1:])
COLUMNS = dict.fromkeys((*REQUIRED, "score"), FLOAT) | {
    "scan": INT, "frame": INT, "track_id": INT, "plot": INT, "tentative": INT, "time": TIME
} | _geodetic.COLUMNS | KINDS


def tracks_from_truth(truth: TruthTable) -> TrackTable:
    """The perfect tracker's output: each target a track (``track_id = target_id``), with
    no plot reference (``plot = -1``)."""
    return TrackTable(
        scan=truth.scan, time=truth.time, track_id=truth.target_id, x=truth.x, y=truth.y,
        vx=truth.vx, vy=truth.vy, plot=np.full(len(truth), NO_PLOT, np.int64),
    )


def has_frames(path: PathArg) -> bool:
    """Whether a tracks file is numbered by ``frame`` (tracks of timed plots, each row at
    its state's own time) rather than by ``scan``."""
    return _numbered_by_frame(column_names(path))


def _numbered_by_frame(names: Sequence[str]) -> bool:
    return "frame" in names and "scan" not in names


def read_tracks(
    path: PathArg, *, accept_truth: bool = True, frame: LocalFrame | None = None,
    plots: PlotTable | None = None, geodetic: bool = False,
) -> TrackTable:
    """Read and validate a tracks file (``.csv`` or ``.parquet``).

    A file with a header and no rows is valid (the tracker reported nothing). Misses
    (empty / null ``plot``) become ``-1``; an explicit negative ``plot`` is an error.
    The covariance ``P`` is not stored in files and is ``None``.

    With ``accept_truth`` (default), a valid *truth* file is also accepted and read as the
    perfect tracker's output (:func:`tracks_from_truth`), so that ``evaluate truth truth``
    checks the metrics' zero point.

    A file with ``lat, lon`` has east/north ``vx, vy``: the local state comes from ``x, y,
    vx_grid, vy_grid``, or from converting with ``frame``
    (:func:`mhtrack.io._geodetic.read_state`). With ``plots`` (the table read from the
    plots file the tracks refer to) the ``plot`` column's file rows become that table's
    rows (:func:`~mhtrack.io.plots.plots_to_table_rows`; a timed file is re-sorted).
    With ``geodetic`` a file with ``lat, lon`` is placed in ``frame`` from them, not from
    its ``x, y`` (:func:`mhtrack.io._geodetic.read_state`).

    Raises
    ------
    InputError : on any problem with the file, naming file, line/row and column.
    """
    try:
        names = column_names(path)
        timed = _numbered_by_frame(names)
        f = read_frame(path, COLUMNS, _geodetic.required(
            names, TIMED_REQUIRED if timed else REQUIRED), "tracks")
    except InputError as tracks_error:
        if not accept_truth or tracks_error.line is not None or tracks_error.row is not None:
            raise
        try:
            truth = read_truth(path, frame=frame)
        except InputError:
            raise tracks_error from None
        return tracks_from_truth(truth)
    scan = f.ints("frame" if timed else "scan")
    time = seconds(f)  # seconds, or ISO-8601 times as POSIX seconds
    tid = f.ints("track_id")
    cols = _geodetic.read_state(f, frame, geodetic=geodetic)
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
    if timed:  # frames in order; each row at its own time
        f.check(np.concatenate(([False], scan[1:] < scan[:-1])), "frame",
                lambda r: f"frame {num(scan[r])} after frame {num(scan[r - 1])}; rows must "
                "be in non-decreasing frame order")
    else:
        check_scan_order(f, scan, time)
    check_unique(f, scan, tid, "track_id")
    if plots is not None:
        rows = plots_to_table_rows(plot, plots)
        f.check(rows == NOT_A_ROW, "plot", lambda r: f"plot {num(plot[r])} is not a row of "
                f"the plots file ({len(plots)} plots)")
        plot = rows
    return TrackTable(scan=scan, time=time, track_id=tid, plot=plot, score=score,
                      tentative=tentative, attrs=read_track_attributes(f), **cols)


def write_tracks(
    table: TrackTable, path: PathArg, frame: LocalFrame | None = None, *,
    plots: PlotTable | None = None,
) -> None:
    """Write ``table`` to a ``.csv`` or ``.parquet`` file; ``plot = -1`` (a miss) is
    written as an empty cell / null, and ``P`` is not stored. With ``frame``, also
    ``lat, lon`` and east/north ``vx, vy`` (:func:`mhtrack.io._geodetic.state_columns`);
    with ``plots`` (the table the tracker ran on), ``plot`` names the row of its file
    (:func:`~mhtrack.io.plots.plots_to_file_rows`). Tracks of timed plots are written
    with ``frame`` in place of ``scan``: their rows have their states' own times. Plots
    read with ISO-8601 times (``plots.iso_times``) give ISO-8601 times here too
    (:func:`~mhtrack.io._times.time_column`)."""
    plot = table.plot if plots is None else plots_to_file_rows(table.plot, plots)
    write_track_rows(replace(table, plot=plot), path, frame,
                     timed=plots is not None and plots.timed,
                     iso=plots is not None and plots.iso_times)


#: Rows per Parquet row group of a tracks file: a file written at the end and one
#: streamed as frames complete (:class:`mhtrack.sinks.TracksFileSink`) have the same bytes.
ROW_GROUP = 4096


def write_track_rows(table: TrackTable, path: PathArg, frame: LocalFrame | None = None, *,
                     timed: bool = False, iso: bool = False,
                     row_group_size: int = ROW_GROUP, attrs: bool | None = None) -> None:
    """Write ``table`` whose ``plot`` already holds the input's own rows (a sink's
    :meth:`~mhtrack.sources.base.Source.file_rows`), as :func:`write_tracks` does; ``timed``:
    rows numbered by ``frame`` (tracks of timed plots), else by ``scan``; ``iso``: times
    as ISO-8601 (the plots' times were; :func:`~mhtrack.io._times.time_column`). Parquet
    row groups of ``row_group_size`` rows."""
    write_frame(path, track_columns(table, file_format(path), frame, timed=timed, iso=iso,
                                    attrs=attrs),
                row_group_size=row_group_size)


def track_columns(table: TrackTable, fmt: str, frame: LocalFrame | None = None, *,
                  timed: bool = False, iso: bool = False, attrs: bool | None = None
                  ) -> dict[str, pa.Array]:
    """The columns :func:`write_track_rows` writes of ``table`` to a ``fmt`` (``"csv"`` or
    ``"parquet"``) file; row by row, so the columns of consecutive slices are the slices
    of the columns. ``attrs``: whether to write the attribute columns
    (:mod:`mhtrack.io.track_attributes`; rows without them empty), default when
    ``table.attrs`` is given."""
    plot = table.plot
    time = time_column(table.time, iso, fmt) if iso else float_array(table.time)
    cols = _geodetic.row_columns(("frame" if timed else "scan", table.scan), time,
                                 ("track_id", table.track_id),
                                 (table.x, table.y, table.vx, table.vy), frame)
    cols["plot"] = int_array(plot, missing=plot == NO_PLOT)
    if table.score is not None:
        cols["score"] = float_array(table.score)
    if table.tentative is not None:
        cols["tentative"] = int_array(table.tentative.astype(np.int64))
    if attrs is None:
        attrs = table.attrs is not None
    if attrs:
        cols.update(track_attribute_columns(
            table.attrs if table.attrs is not None else
            TrackAttributes.absent(len(table), table.P)))
    return cols
