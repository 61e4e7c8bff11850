"""Boundary validation and scan alignment shared by the metrics (private).

Everything here checks its input once and returns plain NumPy arrays; the metric
functions trust those arrays afterwards. :func:`~mhtrack.metrics.evaluate` checks a
(tracks, truth) pair and groups both by scan once, into a :class:`ScanIndexed` value that
every metric works on (``ospa_indexed``, ``clear_mot_indexed``, …); each metric's public
function checks raw tables and builds one when called on its own.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, fields
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

from mhtrack.records import PlotTable, TrackTable, TruthTable

PerScan = TypeVar("PerScan")
#: The array type of each kind of field of a metric's per-scan result.
_DTYPES = {"float": np.float64, "int": np.int64}


def check_cutoff(value: float, name: str) -> float:
    """A cut-off distance: a finite number ``> 0``."""
    v = _as_float(value, name)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{name} must be a finite number > 0 (metres), got {value!r}")
    return v


def check_order(value: float, name: str) -> float:
    """An OSPA/GOSPA order: a finite number ``>= 1``."""
    v = _as_float(value, name)
    if not (math.isfinite(v) and v >= 1.0):
        raise ValueError(f"{name} must be a finite number >= 1, got {value!r}")
    return v


def check_match_distance(value: float, name: str) -> float:
    """A matching distance: a number ``> 0`` (``inf`` allowed: every pair may match)."""
    v = _as_float(value, name)
    if not v > 0.0:  # also rejects NaN
        raise ValueError(f"{name} must be a number > 0 (metres), got {value!r}")
    return v


def _as_float(value: object, name: str) -> float:
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a number, got {value!r}")
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None


def as_points(a: npt.ArrayLike, name: str) -> np.ndarray:
    """A finite ``(k, 2)`` float array; an empty input of any shape gives ``(0, 2)``."""
    arr = np.asarray(a, dtype=np.float64)
    if arr.size == 0:
        return np.zeros((0, 2))
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"{name} must have shape (k, 2), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains non-finite coordinates")
    return arr


def checked_sets(X: npt.ArrayLike, Y: npt.ArrayLike, c: float,
                 p: float) -> tuple[np.ndarray, np.ndarray, float, float]:
    """A set metric's arguments checked: the cut-off ``c`` (finite, ``> 0``), the order ``p``
    (finite, ``>= 1``), then the point sets ``X``, ``Y`` (:func:`as_points`)."""
    c, p = check_cutoff(c, "c"), check_order(p, "p")
    return as_points(X, "X"), as_points(Y, "Y"), c, p


def pairwise_distance(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Euclidean distance matrix ``D[i, j] = ‖X[i] − Y[j]‖`` of shape ``(len(X), len(Y))``."""
    return np.hypot(X[:, None, 0] - Y[None, :, 0], X[:, None, 1] - Y[None, :, 1])


def assigned_distances(X: np.ndarray, Y: np.ndarray, c: float, p: float) -> np.ndarray:
    """The distances ``‖x_i − y_π(i)‖`` of the pairs of the optimal assignment ``π``
    between ``X`` and ``Y`` minimising ``Σ min(d, c)^p`` (the OSPA/GOSPA base distance).

    The cost is computed in units of ``c`` (``(min(d, c)/c)^p`` ∈ [0, 1]) so that large
    ``c^p`` cannot overflow; the minimiser is the same.
    """
    from scipy.optimize import linear_sum_assignment
    D = pairwise_distance(X, Y)
    if D.size == 0:
        return np.zeros(0)
    r, k = linear_sum_assignment((np.minimum(D, c) / c) ** p)
    return D[r, k]


def check_tables(tracks: object, truth: object) -> tuple[TrackTable, TruthTable]:
    """Type-check the (tracks, truth) pair and their columns."""
    if not isinstance(tracks, TrackTable):
        raise TypeError(f"tracks must be a TrackTable, got {type(tracks).__name__}")
    if not isinstance(truth, TruthTable):
        raise TypeError(f"truth must be a TruthTable, got {type(truth).__name__}")
    _check_ids(tracks.scan, tracks.track_id, tracks.positions, "tracks", "track_id")
    _check_ids(truth.scan, truth.target_id, truth.positions, "truth", "target_id")
    return tracks, truth


def _check_ids(scan: np.ndarray, ids: np.ndarray, pos: np.ndarray, what: str, col: str) -> None:
    if len(scan) == 0:
        return
    if not np.all(np.isfinite(pos)):
        raise ValueError(f"{what} has non-finite x/y positions")
    key = np.column_stack((np.asarray(scan, np.int64), np.asarray(ids, np.int64)))
    if len(np.unique(key, axis=0)) != len(key):
        raise ValueError(f"{what} has a repeated ({col}) within one scan")


def check_scans(scans: npt.ArrayLike | None, name: str = "scans") -> np.ndarray:
    """Explicit scan indices as a 1-D int64 array (integral values only)."""
    if scans is None:
        return np.zeros(0, np.int64)
    arr = np.asarray(scans)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence of scan indices, got shape {arr.shape}")
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        f = arr.astype(np.float64)
        if not (np.all(np.isfinite(f)) and np.all(f == np.round(f))):
            raise ValueError(f"{name} must hold integer scan indices")
    return arr.astype(np.int64)


def plot_scans(plots: PlotTable | None) -> np.ndarray:
    """Every scan index of a plot table (empty scans included), or none."""
    if plots is None:
        return np.zeros(0, np.int64)
    if not isinstance(plots, PlotTable):
        raise TypeError(f"plots must be a PlotTable or None, got {type(plots).__name__}")
    return np.asarray(plots.all_scan_times()[0], np.int64)


def scan_union(*scan_arrays: np.ndarray) -> np.ndarray:
    """Sorted union of scan indices."""
    parts = [np.asarray(s, np.int64).ravel() for s in scan_arrays]
    return np.unique(np.concatenate(parts)) if parts else np.zeros(0, np.int64)


class ScanIndex:
    """Rows of a table grouped by scan, looked up for a given list of scans.

    ``rows(k)`` gives, for the ``k``-th requested scan, the table rows at that scan in
    ascending order of ``order_by`` (ids), so results never depend on row order.
    """

    def __init__(self, scan: np.ndarray, order_by: np.ndarray, scans: np.ndarray) -> None:
        self._order = np.lexsort((np.asarray(order_by), np.asarray(scan)))
        sorted_scan = np.asarray(scan)[self._order]
        self._lo = np.searchsorted(sorted_scan, scans, side="left")
        self._hi = np.searchsorted(sorted_scan, scans, side="right")

    def rows(self, k: int) -> np.ndarray:
        return self._order[self._lo[k] : self._hi[k]]

    @property
    def counts(self) -> np.ndarray:
        return self._hi - self._lo


@dataclass(frozen=True)
class ScanIndexed:
    """Checked tracks and truth, with their rows grouped by the scans evaluated.

    ``scans`` is sorted and holds every scan of either table (and any extra scans asked
    for); ``track_rows.rows(k)`` / ``truth_rows.rows(k)`` are the rows at ``scans[k]``, in
    ascending track / target id. Build it with :meth:`build` from checked tables.
    """

    tracks: TrackTable
    truth: TruthTable
    scans: np.ndarray
    track_rows: ScanIndex
    truth_rows: ScanIndex

    def points(self) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Yield ``(truth positions, track positions)`` for each scan of ``scans``."""
        tp, kp = self.truth.positions, self.tracks.positions
        for k in range(len(self.scans)):
            yield tp[self.truth_rows.rows(k)], kp[self.track_rows.rows(k)]

    @classmethod
    def build(cls, tracks: TrackTable, truth: TruthTable, scans: np.ndarray) -> ScanIndexed:
        """Group checked tables by the sorted ``scans`` (which must hold every scan of
        both; :func:`check_tables` first)."""
        return cls(tracks, truth, scans, ScanIndex(tracks.scan, tracks.track_id, scans),
                   ScanIndex(truth.scan, truth.target_id, scans))

    def with_tracks(self, tracks: TrackTable) -> ScanIndexed:
        """The same truth and scans with ``tracks`` — a subset of this value's tracks (e.g.
        their online view), so already checked and within ``scans``."""
        return ScanIndexed(tracks, self.truth, self.scans,
                           ScanIndex(tracks.scan, tracks.track_id, self.scans),
                           self.truth_rows)


def per_scan(cls: type[PerScan], result: type, scans: np.ndarray,
             results: Sequence[Any]) -> PerScan:
    """``cls(scan=scans, f=[r.f for r in results], …)`` for every field ``f`` of the
    dataclass ``result`` (one result per scan): a metric's per-scan arrays, ``float``
    fields as float64 and ``int`` fields as int64 (also when there is no scan)."""
    return cls(scan=scans, **{  # type: ignore[call-arg]
        f.name: np.array([getattr(r, f.name) for r in results], dtype=_DTYPES[str(f.type)])
        for f in fields(result)})


def all_scans(tracks: TrackTable, truth: TruthTable, scans: npt.ArrayLike | None) -> np.ndarray:
    """The union of the truth's scans, the tracks' scans and an explicit list."""
    return scan_union(truth.scan, tracks.scan, check_scans(scans))


def first_time_mismatch(
    scan_a: np.ndarray, time_a: np.ndarray, scan_b: np.ndarray, time_b: np.ndarray,
    *, rtol: float = 1e-6, atol: float = 1e-9,
) -> tuple[int, float, float] | None:
    """The first scan (in scan order) present in both tables whose times differ (beyond
    ``rtol`` relative, ``atol`` absolute), as ``(scan, time in a, time in b)``; ``None``
    when they agree. Each table holds one time per scan (as the file readers check)."""
    ka, ia = np.unique(np.asarray(scan_a, np.int64), return_index=True)
    kb, ib = np.unique(np.asarray(scan_b, np.int64), return_index=True)
    common, ja, jb = np.intersect1d(ka, kb, assume_unique=True, return_indices=True)
    ta = np.asarray(time_a, np.float64)[ia[ja]]
    tb = np.asarray(time_b, np.float64)[ib[jb]]
    bad = np.flatnonzero(~np.isclose(ta, tb, rtol=rtol, atol=atol))
    if bad.size == 0:
        return None
    i = int(bad[0])
    return int(common[i]), float(ta[i]), float(tb[i])


def checked_distance_input(
    tracks: object, truth: object, c: float, p: float, scans: npt.ArrayLike | None
) -> tuple[ScanIndexed, float, float]:
    """The boundary check of the OSPA-family metrics: tables checked and indexed by the
    scans of :func:`all_scans`, cut-off ``c > 0`` and order ``p ≥ 1`` checked."""
    tracks, truth = check_tables(tracks, truth)
    c = check_cutoff(c, "c")
    p = check_order(p, "p")
    return ScanIndexed.build(tracks, truth, all_scans(tracks, truth, scans)), c, p
