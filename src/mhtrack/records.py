"""Immutable records of arrays that flow between the layers of mhtrack.

Data flows one way: scenario → :class:`PlotTable` (scans of plots) → tracker →
:class:`TrackTable` → metrics. Every record is a small frozen dataclass of NumPy arrays,
one row per plot / truth state / track state; nothing here knows how it was produced.

Conventions (all layers):

* positions in metres in a local east-north frame, ``x`` east and ``y`` north;
* a state vector is ``[x, vx, y, vy]`` (P1 §1.1);
* scan indices are integers, times in seconds, non-decreasing with the scan index;
* synchronous data (the papers): every plot of a scan has the scan's time; asynchronous
  data (rotating radars, ``docs/mht.md``): every plot has its own ``time`` and the "scan" is a
  *frame* of one sensor's plots over a short time (:mod:`mhtrack.frames`), flagged by
  ``PlotTable.timed`` and carried to the tracker as ``Scan.t``;
* ``origin`` of a plot is the id of the target that produced it, or ``-1`` for clutter;
* ``plot`` of a track state is the **row index in the plot table** (0-based, the order of
  the rows in the plots file) of the plot the track used at that scan, or ``-1`` on a miss.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mhtrack.attributes import PlotAttributes, TrackAttributes

CLUTTER = -1
NO_PLOT = -1
#: Largest ``|coordinate|`` (m) of the local frame that plots, sensors, regions and target
#: states may have: 10⁹ m is 2.6× the Moon's distance; beyond it squared distances in
#: gating and the clutter fit lose all precision. Checked by the plots reader, the
#: scenario and sensor validation and the tracker.
MAX_COORDINATE = 1e9


def _f8(a: object) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def _i8(a: object) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.int64)


def scan_slices(scan: np.ndarray) -> Iterator[tuple[int, slice]]:
    """Yield ``(scan_index, slice)`` for each run of equal values in a sorted ``scan`` array."""
    if scan.size == 0:
        return
    cuts = np.flatnonzero(np.diff(scan)) + 1
    starts = np.concatenate(([0], cuts))
    stops = np.concatenate((cuts, [scan.size]))
    for a, b in zip(starts.tolist(), stops.tolist(), strict=True):
        yield int(scan[a]), slice(a, b)


@dataclass(frozen=True, slots=True)
class Scan:
    """All plots reported at one scan.

    Attributes
    ----------
    index, time : scan number and its time (s).
    z : (n, 2) Cartesian plot positions (m).
    sensor : (n,) sensor id of each plot.
    rows : (n,) row index of each plot in its :class:`PlotTable` (what tracks refer to).
    R : (n, 2, 2) measurement covariance of each plot, or ``None`` when the tracker's own
        Cartesian ``R`` applies (Cartesian sensors).
    origin : (n,) target id or ``-1`` for clutter; ``None`` when unknown (real data).
    t : (n,) each plot's own time (s) for asynchronous data (a frame of a rotating radar);
        ``None`` when every plot has the scan's ``time`` (synchronous scans). With ``t``,
        ``time`` is the frame's reference time, the latest plot time.
    attrs : what each plot says besides its position (:class:`~mhtrack.attributes.
        PlotAttributes`: code, flight level, address, ...); ``None`` when nothing.
    closing : the byte offset in the input of the radar's sweep mark (CAT034 sector
        crossing) whose arrival closed the frame (``sectors`` frames,
        :mod:`~mhtrack.sources.framer`); ``None`` when something else closed it.
    """

    index: int
    time: float
    z: np.ndarray
    sensor: np.ndarray
    rows: np.ndarray
    R: np.ndarray | None = None
    origin: np.ndarray | None = None
    t: np.ndarray | None = None
    attrs: PlotAttributes | None = None
    closing: int | None = None

    def plot_times(self) -> np.ndarray:
        """(n,) the time of each plot: ``t``, or the scan's ``time`` for every plot."""
        return np.full(len(self), float(self.time)) if self.t is None else self.t

    def __len__(self) -> int:
        return int(self.z.shape[0])

    @classmethod
    def from_positions(
        cls, index: int, time: float, z: np.ndarray, *, sensor: int = 0
    ) -> Scan:
        """A scan of Cartesian plots from one sensor (convenience for library users)."""
        z = _f8(z).reshape(-1, 2)
        n = z.shape[0]
        return cls(int(index), float(time), z, np.full(n, sensor, np.int64), np.arange(n))


@dataclass(frozen=True)
class PlotTable:
    """Plots of many scans, one row per plot, sorted by scan.

    Columns follow the plots file schema (``docs/file-formats.md``):
    ``scan, time, sensor, x, y`` and, for polar sensors, ``range`` (m) and ``bearing``
    (degrees clockwise from north, NaN for Cartesian-sensor rows); ``origin`` when known.
    ``R`` holds each plot's Cartesian measurement covariance when the sensors are polar
    (computed by the sensor model, not stored in files).

    ``scan_times`` optionally lists ``(scan, time)`` of every scan, including scans with
    no plot; :meth:`scans` uses it so an empty scan still reaches the tracker.

    ``timed`` marks asynchronous data: each row's ``time`` is the plot's own time and
    ``scan`` the index of its *frame* (:func:`mhtrack.frames.make_frames`); rows are sorted
    by frame, then time, and :meth:`scans` yields each frame with ``Scan.t``.

    ``file_row`` optionally maps each row to its 0-based row in the file it was read from
    (a timed file is re-sorted on reading); ``None`` when the rows are in file order.
    Tracks refer to the table's rows (``Scan.rows``); writers translate them to file rows.
    ``iso_times``: the file's times were ISO-8601 text or timestamps (kept as POSIX seconds).
    ``attrs``: the plots' attributes (:class:`~mhtrack.attributes.PlotAttributes`), or
    ``None`` when the plots are positions only.
    """

    scan: np.ndarray
    time: np.ndarray
    sensor: np.ndarray
    x: np.ndarray
    y: np.ndarray
    range: np.ndarray | None = None
    bearing: np.ndarray | None = None
    origin: np.ndarray | None = None
    R: np.ndarray | None = None
    scan_times: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)
    timed: bool = False
    file_row: np.ndarray | None = field(default=None, repr=False)
    #: The file gave ISO-8601 (or timestamp) times, read as POSIX seconds: outputs made
    #: from these plots write their times as ISO-8601 too (docs/file-formats.md).
    iso_times: bool = field(default=False, repr=False)
    attrs: PlotAttributes | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        n = len(self.scan)
        for name in ("time", "sensor", "x", "y", "range", "bearing", "origin", "R",
                     "file_row", "attrs"):
            v = getattr(self, name)
            if v is not None and len(v) != n:
                raise ValueError(f"PlotTable column {name!r} has {len(v)} rows, expected {n}")

    def __len__(self) -> int:
        return len(self.scan)

    @property
    def z(self) -> np.ndarray:
        """(n, 2) plot positions."""
        return np.column_stack((self.x, self.y))

    @property
    def n_scans(self) -> int:
        return len(self.all_scan_times()[0])

    def all_scan_times(self) -> tuple[np.ndarray, np.ndarray]:
        """``(scan indices, times)`` of every scan, empty ones included.

        From ``scan_times`` when given; otherwise the scans present in the table, with the
        missing indices between them filled in and their times interpolated linearly.
        """
        if self.scan_times is not None:
            return self.scan_times
        if len(self.scan) == 0:
            return np.zeros(0, np.int64), np.zeros(0)
        if self.timed:  # a frame's time is its latest plot's; frames are never empty
            present, first = np.unique(self.scan, return_index=True)
            return present, np.maximum.reduceat(self.time, first)
        present, first = np.unique(self.scan, return_index=True)
        idx = np.arange(present[0], present[-1] + 1)
        return idx, np.interp(idx, present, self.time[first])

    def scans(self) -> Iterator[Scan]:
        """Yield one :class:`Scan` per scan index, empty scans included, in order."""
        idx, times = self.all_scan_times()
        bounds = dict(scan_slices(self.scan))
        empty = slice(0, 0)
        for k, t in zip(idx.tolist(), times.tolist(), strict=True):
            s = bounds.get(k, empty)
            yield Scan(
                index=k,
                time=t,
                z=np.column_stack((self.x[s], self.y[s])),
                sensor=self.sensor[s],
                rows=np.arange(s.start, s.stop, dtype=np.int64),
                R=None if self.R is None else self.R[s],
                origin=None if self.origin is None else self.origin[s],
                t=self.time[s] if self.timed else None,
                attrs=None if self.attrs is None else self.attrs.take(s),
            )

    @classmethod
    def from_scans(cls, scans: list[Scan]) -> PlotTable:
        """Stack scans (e.g. from a simulator) into one table; rows are renumbered."""
        if not scans:
            e = np.zeros(0)
            return cls(np.zeros(0, np.int64), e, np.zeros(0, np.int64), e, e)
        n = [len(s) for s in scans]
        z = np.concatenate([s.z for s in scans]).reshape(-1, 2)
        has_r = any(s.R is not None for s in scans)
        has_o = all(s.origin is not None for s in scans)
        attrs = None
        if any(s.attrs is not None for s in scans):
            attrs = PlotAttributes.concat([s.attrs if s.attrs is not None else
                                           PlotAttributes.absent(len(s)) for s in scans])
        return cls(
            scan=_i8(np.repeat([s.index for s in scans], n)),
            time=_f8(np.repeat([s.time for s in scans], n)),
            sensor=_i8(np.concatenate([s.sensor for s in scans])),
            x=_f8(z[:, 0]),
            y=_f8(z[:, 1]),
            origin=_i8(np.concatenate([s.origin for s in scans])) if has_o else None,
            R=np.concatenate(
                [s.R if s.R is not None else np.full((len(s), 2, 2), np.nan) for s in scans]
            )
            if has_r
            else None,
            scan_times=(_i8([s.index for s in scans]), _f8([s.time for s in scans])),
            attrs=attrs,
        )


@dataclass(frozen=True)
class TruthTable:
    """True target states, one row per (scan, live target): ``scan, time, target_id, x, y,
    vx, vy``, sorted by scan then target id."""

    scan: np.ndarray
    time: np.ndarray
    target_id: np.ndarray
    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray

    def __len__(self) -> int:
        return len(self.scan)

    @property
    def positions(self) -> np.ndarray:
        return np.column_stack((self.x, self.y))


@dataclass(frozen=True)
class TrackTable:
    """Tracker output, one row per (scan, reported track): ``scan, time, track_id, x, y, vx,
    vy, plot`` (``plot`` = plot-table row used at that scan, ``-1`` on a miss), optionally
    the track ``score`` (log-likelihood ratio), state covariance ``P`` (n, 4, 4) and
    ``tentative`` (bool: the row was reported after the scan, when the track was confirmed
    later, see :mod:`mhtrack.mht.history`) and, when the plots had attributes, ``attrs``
    (:class:`~mhtrack.attributes.TrackAttributes`: flight level, codes, accuracy); with
    an IMM tracker asked for them (:attr:`MHTTracker.keep_models
    <mhtrack.mht.MHTTracker.keep_models>`, for :mod:`mhtrack.models.smoother`), each
    model's filtered state: probabilities ``mu`` (n, r), states ``xm`` (n, r, 4),
    covariances ``Pm`` (n, r, 4, 4). Files never carry the model states."""

    scan: np.ndarray
    time: np.ndarray
    track_id: np.ndarray
    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    plot: np.ndarray
    score: np.ndarray | None = None
    P: np.ndarray | None = None
    tentative: np.ndarray | None = None
    attrs: TrackAttributes | None = field(default=None, repr=False)
    mu: np.ndarray | None = field(default=None, repr=False)
    xm: np.ndarray | None = field(default=None, repr=False)
    Pm: np.ndarray | None = field(default=None, repr=False)

    def __len__(self) -> int:
        return len(self.scan)

    @property
    def positions(self) -> np.ndarray:
        return np.column_stack((self.x, self.y))

    def take(self, idx: np.ndarray) -> TrackTable:
        """Rows ``idx`` (an index array or boolean mask), in that order."""
        return TrackTable(**{f: None if (v := getattr(self, f)) is None else v[idx]
                             for f in self.__dataclass_fields__})

    def sorted(self) -> TrackTable:
        """Rows ordered by scan, then track id (stable)."""
        return self.take(np.lexsort((self.track_id, self.scan)))

    def online(self) -> TrackTable:
        """The rows reported at their own scan (``tentative`` false or absent)."""
        return self if self.tentative is None else self.take(~self.tentative.astype(bool))

    @classmethod
    def empty(cls) -> TrackTable:
        e = np.zeros(0)
        i = np.zeros(0, np.int64)
        return cls(i, e, i, e, e, e, e, i)

    def to_pandas(self) -> Any:
        """A :class:`pandas.DataFrame`, one row per track row: the columns ``scan, time,
        track_id, x, y, vx, vy, plot`` and, when present, ``score``, ``tentative`` (bool)
        and ``P00 … P33`` (the covariance, row-major). Needs pandas (not a dependency of
        mhtrack): :class:`ImportError` naming it otherwise."""
        pd = _pandas("TrackTable.to_pandas")
        cols: dict[str, np.ndarray] = {f: getattr(self, f) for f in _TRACK_COLUMNS}
        for f in ("score", "tentative"):
            if (v := getattr(self, f)) is not None:
                cols[f] = v.astype(bool) if f == "tentative" else v
        if self.P is not None:
            for i, j in np.ndindex(4, 4):
                cols[f"P{i}{j}"] = self.P[:, i, j]
        return pd.DataFrame(cols)

    @classmethod
    def from_pandas(cls, df: Any) -> TrackTable:
        """The table of a DataFrame as :meth:`to_pandas` makes it (``score``,
        ``tentative`` and ``P00 … P33`` optional; a missing required column is a
        :class:`ValueError` naming it)."""
        _pandas("TrackTable.from_pandas")
        missing = [c for c in _TRACK_COLUMNS if c not in df.columns]
        if missing:
            raise ValueError(f"DataFrame lacks column(s) {', '.join(missing)} (a tracks "
                             f"table needs {', '.join(_TRACK_COLUMNS)})")
        ints = ("scan", "track_id", "plot")
        kw: dict[str, Any] = {c: df[c].to_numpy(np.int64 if c in ints else np.float64)
                              for c in _TRACK_COLUMNS}
        if "score" in df.columns:
            kw["score"] = df["score"].to_numpy(np.float64)
        if "tentative" in df.columns:
            kw["tentative"] = df["tentative"].to_numpy(bool)
        names = [f"P{i}{j}" for i, j in np.ndindex(4, 4)]
        if all(n in df.columns for n in names):
            kw["P"] = np.stack([df[n].to_numpy(np.float64) for n in names],
                               axis=1).reshape(-1, 4, 4)
        return cls(**kw)

    @classmethod
    def concat(cls, parts: list[TrackTable]) -> TrackTable:
        """Concatenate per-scan outputs, in order."""
        parts = [p for p in parts if len(p)]
        if not parts:
            return cls.empty()

        def cat(name: str) -> np.ndarray | None:
            vals = [getattr(p, name) for p in parts]
            return None if any(v is None for v in vals) else np.concatenate(vals)

        attrs = None  # parts without attributes (a tentative past): absent, but accuracy
        if any(p.attrs is not None for p in parts):
            attrs = TrackAttributes.concat([
                p.attrs if p.attrs is not None else TrackAttributes.absent(len(p), p.P)
                for p in parts])
        return cls(**{f: cat(f) for f in cls.__dataclass_fields__ if f != "attrs"},
                   attrs=attrs)  # type: ignore[arg-type]


#: The required columns of a tracks table, in order.
_TRACK_COLUMNS = ("scan", "time", "track_id", "x", "y", "vx", "vy", "plot")


def _pandas(what: str) -> Any:
    """pandas, or :class:`ImportError` saying ``what`` needs it."""
    try:
        import pandas
    except ImportError as e:
        raise ImportError(f"{what} needs pandas (not installed with mhtrack): "
                          "pip install 'mhtrack[pandas]' (or pip install pandas)") from e
    return pandas
