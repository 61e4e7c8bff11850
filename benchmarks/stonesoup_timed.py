"""Stone Soup's GNN and JPDA trackers on timed plots (rotating radars), for ``bench_async``.

Stone Soup takes per-detection timestamps and measurement models natively: each plot
becomes ``Detection(z, timestamp=t_i, measurement_model=LinearGaussian(4, (0, 2), R_i))``
with the plot's own time and the covariance of its polar-to-local conversion — the same
``x, y, R`` that mhtrack tracks. The detections are fed in time order, grouped as mhtrack
groups them: one set per *frame* (one radar's 45° sweep sector, ``PlotTable.scans()``).
The hypothesisers predict each track to each detection's own time, so gating and
likelihoods are exact per plot.

Components (Stone Soup 1.x): a nearly-constant-velocity transition model
(``ConstantVelocity(q)`` per axis, ``q`` in m²/s³), a Kalman predictor/updater, a
``PDAHypothesiser`` per radar with that radar's ``P_D`` and mean clutter density (the
frame's radar picks it, :class:`PerSensorAssociator`), and ``GNNWith2DAssignment`` (tracker
``MultiTargetTracker``) or ``JPDAwithEHM`` (``MultiTargetMixtureTracker``). New tracks come
from ``MultiMeasurementInitiator`` (GNN over Mahalanobis distance, ``min_points`` plots);
tracks without an update for ``delete_s`` seconds are deleted (``UpdateTimeDeleter``:
a radar that did not look gives no update, so a step count would delete every track
between two sweeps).
"""

from __future__ import annotations

import datetime
import time
from dataclasses import dataclass

import numpy as np

from mhtrack.records import PlotTable, TrackTable

EPOCH = datetime.datetime(2020, 1, 1)


@dataclass(frozen=True)
class StoneSoupRun:
    """One Stone Soup run: the live view (each step's tracks at that step), the whole
    histories (every state of every track, ``track.states``), and the tracker's seconds."""

    online: TrackTable
    history: TrackTable
    wall: float
    n_steps: int


def _table(rows: list[tuple[int, float, int, float, float, float, float]]) -> TrackTable:
    """Rows ``(frame, time, track, x, y, vx, vy)`` as a TrackTable, one row per frame and
    track (the latest), as mhtrack reports."""
    if not rows:
        return TrackTable.empty()
    a = np.array(rows)
    a = a[np.lexsort((a[:, 1], a[:, 2], a[:, 0]))]  # by frame, track, time
    last = np.ones(len(a), bool)  # one row per (frame, track): its latest state
    last[:-1] = (a[1:, 0] != a[:-1, 0]) | (a[1:, 2] != a[:-1, 2])
    a = a[last]
    return TrackTable(
        scan=a[:, 0].astype(np.int64), time=a[:, 1], track_id=a[:, 2].astype(np.int64),
        x=a[:, 3], y=a[:, 4], vx=a[:, 5], vy=a[:, 6], plot=np.full(len(a), -1, np.int64),
    )


def _seconds(ts: datetime.datetime) -> float:
    return (ts - EPOCH).total_seconds()


def run_stonesoup_timed(
    plots: PlotTable, *, pd: dict[int, float], clutter_density: dict[int, float],
    kind: str = "jpda", q: float = 1.0, min_points: int = 3, delete_s: float = 40.0,
    init_delete_s: float = 13.0, sigma_speed: float = 300.0, grouping: str = "frame",
) -> StoneSoupRun:
    """Track the timed ``plots`` with Stone Soup (``kind`` ``"gnn"`` or ``"jpda"``).

    ``pd`` and ``clutter_density`` (per m² per look) are per sensor id; ``q`` the CV
    process-noise intensity (m²/s³); ``sigma_speed`` the initiator's prior velocity σ
    (m/s). ``grouping``: one step per frame (``"frame"``), or per distinct plot time
    (``"time"``: exact for JPDA's mixture, which merges a track's hypotheses into one
    state labelled with one time; per frame the missed-detection prediction at the frame's
    end and updates at the plots' earlier times are merged). The tracker alone is timed
    (the detections are built before)."""
    from stonesoup.base import Property
    from stonesoup.dataassociator.base import DataAssociator
    from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
    from stonesoup.dataassociator.probability import JPDAwithEHM
    from stonesoup.deleter.time import UpdateTimeDeleter
    from stonesoup.hypothesiser.distance import DistanceHypothesiser
    from stonesoup.hypothesiser.probability import PDAHypothesiser
    from stonesoup.initiator.simple import MultiMeasurementInitiator
    from stonesoup.measures import Mahalanobis
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import (
        CombinedLinearGaussianTransitionModel,
        ConstantVelocity,
    )
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.tracker.simple import MultiTargetMixtureTracker, MultiTargetTracker
    from stonesoup.types.detection import Detection
    from stonesoup.types.state import GaussianState
    from stonesoup.updater.kalman import KalmanUpdater

    class PerSensorAssociator(DataAssociator):
        """The associator of the radar whose frame is being processed (every detection
        of a frame comes from one radar; ``metadata["sensor"]``)."""

        by_sensor: dict = Property(doc="sensor id -> DataAssociator")

        def associate(self, tracks: set, detections: set, timestamp: datetime.datetime,
                      **kwargs: object) -> dict:
            if not detections:
                any_assoc = next(iter(self.by_sensor.values()))
                return any_assoc.associate(tracks, detections, timestamp, **kwargs)
            sensor = next(iter(detections)).metadata["sensor"]
            return self.by_sensor[sensor].associate(tracks, detections, timestamp, **kwargs)

    if grouping not in ("frame", "time"):
        raise ValueError(f"grouping must be 'frame' or 'time', got {grouping!r}")
    if kind not in ("gnn", "jpda"):
        raise ValueError(f"kind must be 'gnn' or 'jpda', got {kind!r}")
    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(q), ConstantVelocity(q)])
    predictor = KalmanPredictor(transition)
    updater = KalmanUpdater(measurement_model=None)  # each detection brings its model
    assoc_cls = GNNWith2DAssignment if kind == "gnn" else JPDAwithEHM
    by_sensor = {
        s: assoc_cls(PDAHypothesiser(predictor, updater,
                                     clutter_spatial_density=clutter_density[s],
                                     prob_detect=pd[s], prob_gate=0.999))
        for s in pd
    }
    associator = PerSensorAssociator(next(iter(by_sensor.values())).hypothesiser,
                                     by_sensor=by_sensor)
    initiator = MultiMeasurementInitiator(
        prior_state=GaussianState(np.zeros((4, 1)),
                                  np.diag([0.0, sigma_speed**2, 0.0, sigma_speed**2])),
        measurement_model=None,
        deleter=UpdateTimeDeleter(datetime.timedelta(seconds=init_delete_s)),
        data_associator=GNNWith2DAssignment(
            DistanceHypothesiser(predictor, updater, Mahalanobis(), missed_distance=3)),
        updater=updater, min_points=min_points,
    )
    feed = []  # (step time, detections)
    steps = []  # frame index of each step
    frames = []  # (frame index, frame time)
    for sc in plots.scans():
        groups: dict[float, set] = {}
        for z, R, ti, s in zip(sc.z, sc.R, sc.plot_times(), sc.sensor, strict=True):
            model = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.asarray(R))
            key = float(ti) if grouping == "time" else float(sc.time)
            groups.setdefault(key, set()).add(Detection(
                z.reshape(2, 1), timestamp=EPOCH + datetime.timedelta(seconds=float(ti)),
                measurement_model=model, metadata={"sensor": int(s)}))
        for t, dets in sorted(groups.items()) or [(float(sc.time), set())]:
            feed.append((EPOCH + datetime.timedelta(seconds=t), dets))
            steps.append(sc.index)
        frames.append((sc.index, float(sc.time)))
    tracker_cls = MultiTargetTracker if kind == "gnn" else MultiTargetMixtureTracker
    tracker = tracker_cls(initiator=initiator, deleter=UpdateTimeDeleter(
        datetime.timedelta(seconds=delete_s)), detector=feed, data_associator=associator,
        updater=updater)
    ids: dict[int, int] = {}
    seen: dict[int, object] = {}
    online: list[tuple[int, float, int, float, float, float, float]] = []
    wall = 0.0
    it = iter(tracker)
    for index in steps:
        t0 = time.perf_counter()
        _, tracks = next(it)
        wall += time.perf_counter() - t0
        for trk in tracks:
            tid = ids.setdefault(id(trk), len(ids))
            seen[tid] = trk
            st = trk.state
            m = np.asarray(st.state_vector, float).ravel()
            online.append((index, _seconds(st.timestamp), tid, m[0], m[2], m[1], m[3]))
    frame_index = np.array([f[0] for f in frames])
    frame_time = np.array([f[1] for f in frames])
    history = []
    for tid, trk in seen.items():
        last: dict[int, object] = {}  # frame -> the track's latest state in it
        for st in trk.states:
            ts = _seconds(st.timestamp)
            k = int(frame_index[min(np.searchsorted(frame_time, ts - 1e-9), len(frames) - 1)])
            last[k] = st
        for k, st in last.items():
            m = np.asarray(st.state_vector, float).ravel()
            history.append((k, _seconds(st.timestamp), tid, m[0], m[2], m[1], m[3]))
    return StoneSoupRun(_table(online), _table(history), wall, len(steps))
