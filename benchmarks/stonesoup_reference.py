"""Stone Soup's JPDA tracker on mhtrack plots, for the speed/accuracy comparison.

Stone Soup (installed for benchmarks only: ``pip install -e ".[reference]"``) runs its
multi-target mixture tracker: JPDA with EHM (``JPDAwithEHM``) over a PDA hypothesiser,
a multi-measurement initiator (GNN on 2-D assignment, confirm after 4 plots: of 3 and 4, 4
gave Stone Soup the better OSPA on crossing, 200 m against 336 m) and a
deleter that drops tracks without an update for 3 steps. Same motion and measurement
models, detection probability and clutter density as the mhtrack run.
"""

from __future__ import annotations

import datetime
import time

import numpy as np

from mhtrack.records import PlotTable, TrackTable


def run_stonesoup_jpda(
    plots: PlotTable, *, sigma_w: float, sigma_v: float, p_detection: float,
    clutter_density: float, kind: str = "jpda",
) -> tuple[TrackTable, np.ndarray]:
    """Track ``plots`` with Stone Soup's JPDA (``kind="gnn"``: GNN with 2-D assignment on
    the same PDA hypotheses, ``MultiTargetTracker``); return its tracks and seconds per
    scan."""
    from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
    from stonesoup.dataassociator.probability import JPDAwithEHM
    from stonesoup.deleter.time import UpdateTimeStepsDeleter
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

    transition = CombinedLinearGaussianTransitionModel(
        [ConstantVelocity(sigma_v**2), ConstantVelocity(sigma_v**2)]
    )
    meas = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2) * sigma_w**2)
    predictor = KalmanPredictor(transition)
    updater = KalmanUpdater(meas)
    hyp = PDAHypothesiser(predictor, updater, clutter_spatial_density=clutter_density,
                          prob_detect=p_detection, prob_gate=0.999)
    associator = GNNWith2DAssignment(hyp) if kind == "gnn" else JPDAwithEHM(hyp)
    deleter = UpdateTimeStepsDeleter(3)
    init_assoc = GNNWith2DAssignment(
        DistanceHypothesiser(predictor, updater, Mahalanobis(), missed_distance=3)
    )
    initiator = MultiMeasurementInitiator(
        prior_state=GaussianState(np.zeros((4, 1)), np.diag([0, 150.0**2, 0, 150.0**2])),
        measurement_model=meas, deleter=UpdateTimeStepsDeleter(2),
        data_associator=init_assoc, updater=updater, min_points=4,
    )
    epoch = datetime.datetime(2020, 1, 1)
    scans = list(plots.scans())
    feed = [
        (epoch + datetime.timedelta(seconds=float(sc.time)),
         {Detection(z.reshape(2, 1), timestamp=epoch + datetime.timedelta(
             seconds=float(sc.time)), measurement_model=meas) for z in sc.z})
        for sc in scans
    ]
    tracker_class = MultiTargetTracker if kind == "gnn" else MultiTargetMixtureTracker
    tracker = tracker_class(
        initiator=initiator, deleter=deleter, detector=feed, data_associator=associator,
        updater=updater,
    )
    it = iter(tracker)
    rows: list[tuple[int, float, int, float, float, float, float]] = []
    ids: dict[int, int] = {}
    seconds = []
    for sc in scans:
        t0 = time.perf_counter()
        _, tracks = next(it)
        seconds.append(time.perf_counter() - t0)
        for trk in tracks:
            tid = ids.setdefault(id(trk), len(ids))
            m = np.asarray(trk.state.state_vector, float).ravel()
            rows.append((sc.index, float(sc.time), tid, m[0], m[2], m[1], m[3]))
    if not rows:
        return TrackTable.empty(), np.array(seconds)
    a = np.array(rows)
    out = TrackTable(
        scan=a[:, 0].astype(np.int64), time=a[:, 1], track_id=a[:, 2].astype(np.int64),
        x=a[:, 3], y=a[:, 4], vx=a[:, 5], vy=a[:, 6], plot=np.full(len(a), -1, np.int64),
    )
    order = np.lexsort((out.track_id, out.scan))
    return TrackTable(**{k: getattr(out, k)[order] if getattr(out, k) is not None else None
                         for k in out.__dataclass_fields__}), np.array(seconds)
