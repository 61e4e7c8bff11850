"""Stone Soup detections, ground truth and tracks ↔ mhtrack's tables.

A Stone Soup detection carries its measurement model; each becomes an mhtrack plot — a
Cartesian position ``z = (x, y)`` in metres with its own covariance ``R`` (2×2) — by the
exact inverse of its model and the first-order covariance through its Jacobian:

* ``LinearGaussian``: ``z`` = the measurement's components that the model's ``mapping``
  takes from the state's position indices ``position_mapping`` (Stone Soup's ``(0, 2)``
  for a state ``(x, vx, y, vy)``), ``R`` = the matching block of ``noise_covar``;
* ``CartesianToBearingRange`` (measurement ``(φ, r)``): ``u = (r cos φ, r sin φ, 0)``,
  ``(x, y) = (M⁻¹ u)[:2] + t`` with ``M`` the model's rotation matrix and ``t`` its
  translation offset — the model's ``inverse_function`` — and ``R = J R_m Jᵀ`` with
  ``J = M⁻¹[:2, :2] [[−r sin φ, cos φ], [r cos φ, sin φ]]`` (columns ``φ, r``);
* ``CartesianToElevationBearingRange`` (measurement ``(θ, φ, r)``):
  ``u = (r cos φ cos θ, r sin φ cos θ, r sin θ)``, ``(x, y) = (M⁻¹ u + t)[:2]`` and
  ``R`` the ``(x, y)`` block of ``J R_m Jᵀ``, ``J = M⁻¹ ∂u/∂(θ, φ, r)``: the plot is the
  horizontal position, the height is dropped (mhtrack tracks in the plane).

Times: Stone Soup's ``datetime`` become seconds after an ``epoch`` (the first step's time
unless given).
"""

from __future__ import annotations

import datetime
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.measurement.nonlinear import (
    CartesianToBearingRange,
    CartesianToElevationBearingRange,
)
from stonesoup.types.detection import Clutter, TrueDetection
from stonesoup.types.state import GaussianState, State
from stonesoup.types.track import Track

from mhtrack.records import PlotTable, Scan, TrackTable, TruthTable

#: Indices of ``x`` and ``y`` in Stone Soup's state vector ``(x, vx, y, vy)``.
POSITION_MAPPING = (0, 2)
#: Indices of ``vx`` and ``vy``.
VELOCITY_MAPPING = (1, 3)

SUPPORTED_MODELS = "LinearGaussian, CartesianToBearingRange, CartesianToElevationBearingRange"


def seconds(t: datetime.datetime, epoch: datetime.datetime) -> float:
    """``t`` in seconds after ``epoch``."""
    return (t - epoch).total_seconds()


def detections_to_xy(
    detections: Sequence[Any], *, position_mapping: Sequence[int] = POSITION_MAPPING,
    measurement_model: Any = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Positions ``(n, 2)`` and covariances ``(n, 2, 2)`` of Stone Soup detections (module
    docstring), in the order given. Detections that share a model object are converted
    together. ``measurement_model`` is used for detections that carry none."""
    n = len(detections)
    z, R = np.zeros((n, 2)), np.zeros((n, 2, 2))
    groups: dict[int, tuple[Any, list[int]]] = {}
    for i, det in enumerate(detections):
        model = det.measurement_model
        model = measurement_model if model is None else model
        if model is None:
            raise ValueError(f"detection at {det.timestamp} has no measurement model "
                             f"(expected one of {SUPPORTED_MODELS})")
        groups.setdefault(id(model), (model, []))[1].append(i)
    for model, idx in groups.values():
        sv = np.hstack([np.asarray(detections[i].state_vector, dtype=np.float64)
                        for i in idx])
        z[idx], R[idx] = _convert(model, sv, tuple(position_mapping))
    return z, R


def _convert(model: Any, sv: np.ndarray, pos: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """``(z, R)`` of the measurements ``sv`` (ndim_meas, n) of one model."""
    mapping = tuple(int(m) for m in model.mapping)
    Rm = np.asarray(model.covar(), dtype=np.float64)
    if isinstance(model, LinearGaussian):
        if not set(pos) <= set(mapping):
            raise ValueError(f"LinearGaussian mapping {mapping} does not measure the "
                             f"position indices {pos}")
        rows = [mapping.index(p) for p in pos]
        return sv[rows].T.copy(), np.broadcast_to(Rm[np.ix_(rows, rows)],
                                                  (sv.shape[1], 2, 2))
    if mapping[:2] != pos:
        raise ValueError(f"{type(model).__name__} mapping {mapping} does not start with the "
                         f"position indices {pos}")
    Minv = np.linalg.inv(np.asarray(model.rotation_matrix, dtype=np.float64))
    t = np.asarray(model.translation_offset, dtype=np.float64).ravel()
    if isinstance(model, CartesianToBearingRange):
        rot = np.asarray(model.rotation_offset, dtype=np.float64).ravel()
        if rot[0] != 0 or rot[1] != 0:
            raise ValueError("CartesianToBearingRange with a rotation about x or y is not "
                             "a 2-D model (Stone Soup's inverse_function refuses it too)")
        phi, r = sv[0], sv[1]
        c, s = np.cos(phi), np.sin(phi)
        A = Minv[:2, :2]
        z = (A @ np.vstack((r * c, r * s))).T + t[:2]
        Ju = np.stack((np.stack((-r * s, c), -1), np.stack((r * c, s), -1)), 1)  # (n,2,2)
        J = A @ Ju
        return z, J @ Rm @ J.transpose(0, 2, 1)
    if isinstance(model, CartesianToElevationBearingRange):
        th, phi, r = sv[0], sv[1], sv[2]
        ct, st, cp, sp = np.cos(th), np.sin(th), np.cos(phi), np.sin(phi)
        u = np.vstack((r * cp * ct, r * sp * ct, r * st))
        z = (Minv @ u).T[:, :2] + t[:2]
        zero = np.zeros_like(r)
        Ju = np.stack((np.stack((-r * cp * st, -r * sp * ct, cp * ct), -1),
                       np.stack((-r * sp * st, r * cp * ct, sp * ct), -1),
                       np.stack((r * ct, zero, st), -1)), 1)  # (n, 3, 3), columns θ, φ, r
        J = (Minv @ Ju)[:, :2, :]
        return z, J @ Rm @ J.transpose(0, 2, 1)
    raise ValueError(f"measurement model {type(model).__name__} is not supported "
                     f"(expected one of {SUPPORTED_MODELS})")


def detections_to_plots(
    feed: Iterable[tuple[datetime.datetime, Iterable[Any]]], *,
    epoch: datetime.datetime | None = None,
    position_mapping: Sequence[int] = POSITION_MAPPING,
    measurement_model: Any = None,
    truth_ids: dict[Any, int] | None = None,
) -> PlotTable:
    """A Stone Soup detector's output — ``(time, detections)`` steps — as a
    :class:`PlotTable`: one scan per distinct detection time of each step
    (:func:`split_by_time`, as :class:`~mhtrack.stonesoup.MHTrackTracker` reads them; scan
    ``k`` at ``seconds(t, epoch)``), positions and ``R`` by :func:`detections_to_xy`.
    ``origin``: with ``truth_ids`` (ground-truth path → target id, from
    :func:`ground_truth_to_table`) each ``TrueDetection`` gets its path's id and each
    ``Clutter`` ``−1``; detections of other types make the column absent."""
    scans: list[Scan] = []
    row = 0
    has_origin = truth_ids is not None
    steps = ((t, d) for time, dets in feed for t, d in split_by_time(time, dets))
    for k, (time, d) in enumerate(steps):
        epoch = time if epoch is None else epoch
        z, R = detections_to_xy(d, position_mapping=position_mapping,
                                measurement_model=measurement_model)
        origin = _origins(d, truth_ids) if has_origin else None
        has_origin = has_origin and origin is not None
        n = len(d)
        scans.append(Scan(k, seconds(time, epoch), z, np.array(
            [int(x.metadata.get("sensor", 0)) for x in d], np.int64), np.arange(row, row + n),
            R, origin))
        row += n
    if not has_origin:
        scans = [Scan(s.index, s.time, s.z, s.sensor, s.rows, s.R) for s in scans]
    return PlotTable.from_scans(scans)


def _origins(dets: Sequence[Any], truth_ids: dict[Any, int] | None) -> np.ndarray | None:
    out = np.full(len(dets), -1, np.int64)
    for i, d in enumerate(dets):
        if isinstance(d, TrueDetection):
            out[i] = (truth_ids or {}).get(d.groundtruth_path, -1)
        elif not isinstance(d, Clutter):
            return None
    return out


def split_by_time(time: datetime.datetime, detections: Iterable[Any]
                  ) -> list[tuple[datetime.datetime, list[Any]]]:
    """One detector step as mhtrack scans: one ``(timestamp, detections)`` per distinct
    detection timestamp (a detection without one takes the step's ``time``), in time
    order, each sorted by :func:`sort_detections`; ``[(time, [])]`` for an empty step."""
    groups: dict[datetime.datetime, list[Any]] = {}
    for d in detections:
        groups.setdefault(time if d.timestamp is None else d.timestamp, []).append(d)
    if not groups:
        return [(time, [])]
    return [(t, sort_detections(groups[t])) for t in sorted(groups)]


def sort_detections(detections: Iterable[Any]) -> list[Any]:
    """Detections in a reproducible order (a Stone Soup step is a ``set``): by timestamp,
    then measurement vector."""
    d = list(detections)
    key = [(x.timestamp or datetime.datetime.min,
            tuple(np.asarray(x.state_vector, dtype=np.float64).ravel().tolist())) for x in d]
    return [d[i] for i in sorted(range(len(d)), key=key.__getitem__)]


def ground_truth_to_table(
    paths: Iterable[Any], epoch: datetime.datetime,
    times: Sequence[datetime.datetime] | None = None, *,
    position_mapping: Sequence[int] = POSITION_MAPPING,
    velocity_mapping: Sequence[int] = VELOCITY_MAPPING,
) -> tuple[TruthTable, dict[Any, int]]:
    """Stone Soup ground-truth paths as a :class:`TruthTable` and the id given to each path
    (0, 1, … by first timestamp, then path id). Scan ``k`` is ``times[k]`` (e.g. the
    detector's step times; states at other times are left out), or the ``k``-th distinct
    timestamp of the paths."""
    paths = sorted(paths, key=lambda p: (p.states[0].timestamp, str(p.id)) if len(p.states)
                   else (datetime.datetime.max, str(p.id)))
    if times is None:
        times = sorted({s.timestamp for p in paths for s in p.states})
    index = {t: k for k, t in enumerate(times)}
    ids = {p: i for i, p in enumerate(paths)}
    rows = []
    for p, i in ids.items():
        for s in p.states:
            k = index.get(s.timestamp)
            if k is not None:
                v = np.asarray(s.state_vector, dtype=np.float64).ravel()
                rows.append((k, seconds(s.timestamp, epoch), i, v[position_mapping[0]],
                             v[position_mapping[1]], v[velocity_mapping[0]],
                             v[velocity_mapping[1]]))
    a = np.array(rows, dtype=np.float64).reshape(-1, 7)
    a = a[np.lexsort((a[:, 2], a[:, 0]))]
    return TruthTable(a[:, 0].astype(np.int64), a[:, 1], a[:, 2].astype(np.int64),
                      a[:, 3], a[:, 4], a[:, 5], a[:, 6]), ids


def table_to_tracks(tracks: TrackTable, epoch: datetime.datetime) -> set[Any]:
    """An mhtrack :class:`TrackTable` as Stone Soup ``Track`` objects (``id`` =
    ``"mhtrack-<track id>"``), states in time order: ``GaussianState`` (mean
    ``(x, vx, y, vy)``, covariance ``P``) when the table has ``P``, else ``State``."""
    out = set()
    for tid in np.unique(tracks.track_id):
        rows = np.flatnonzero(tracks.track_id == tid)
        rows = rows[np.argsort(tracks.time[rows], kind="stable")]
        out.add(Track([state_of(tracks, r, epoch + datetime.timedelta(
            seconds=float(tracks.time[r]))) for r in rows], id=f"mhtrack-{int(tid)}"))
    return out


def state_of(tracks: TrackTable, r: int, timestamp: datetime.datetime) -> Any:
    """Row ``r`` as a Stone Soup ``GaussianState`` (``State`` without ``P``)."""
    mean = np.array([[tracks.x[r]], [tracks.vx[r]], [tracks.y[r]], [tracks.vy[r]]])
    if tracks.P is None:
        return State(mean, timestamp=timestamp)
    return GaussianState(mean, tracks.P[r], timestamp=timestamp)


def tracks_to_table(
    tracks: Iterable[Any], epoch: datetime.datetime, times: Sequence[datetime.datetime], *,
    position_mapping: Sequence[int] = POSITION_MAPPING,
    velocity_mapping: Sequence[int] = VELOCITY_MAPPING,
) -> TrackTable:
    """Stone Soup tracks (any tracker's) as a :class:`TrackTable` on the scans
    ``times[k]``: a track's last state at each of these times (states at other times are
    left out); track ids 0, 1, … by first timestamp, then track id. ``plot`` is −1."""
    index = {t: k for k, t in enumerate(times)}
    tracks = sorted(tracks, key=lambda t: (t.states[0].timestamp, str(t.id)) if len(t.states)
                    else (datetime.datetime.max, str(t.id)))
    rows: dict[tuple[int, int], tuple[float, ...]] = {}
    for i, trk in enumerate(tracks):
        for s in trk.states:
            k = index.get(s.timestamp)
            if k is not None:
                v = np.asarray(s.state_vector, dtype=np.float64).ravel()
                rows[(k, i)] = (k, seconds(s.timestamp, epoch), i, v[position_mapping[0]],
                                v[position_mapping[1]], v[velocity_mapping[0]],
                                v[velocity_mapping[1]])
    a = np.array(sorted(rows.values()), dtype=np.float64).reshape(-1, 7)
    return TrackTable(a[:, 0].astype(np.int64), a[:, 1], a[:, 2].astype(np.int64), a[:, 3],
                      a[:, 4], a[:, 5], a[:, 6], np.full(len(a), -1, np.int64))
