"""mhtrack's MHT next to Stone Soup's GNN and JPDA trackers, all inside Stone Soup.

Stone Soup's own simulators make the scene: a multi-target ground truth
(``MultiTargetGroundTruthSimulator``: nearly-constant-velocity targets born and dying at
random) and its detections (``SimpleDetectionSimulator``: ``P_D`` 0.9, position noise
σ = 30 m, uniform clutter). The detections are recorded once, and every tracker reads
the same steps:

* Stone Soup GNN: ``GlobalNearestNeighbour`` over a Mahalanobis ``DistanceHypothesiser``
  (``MultiTargetTracker``);
* Stone Soup JPDA: ``JPDA`` over a ``PDAHypothesiser`` with the true ``P_D`` and clutter
  density (``MultiTargetMixtureTracker``);
* both with Kalman filters on the simulator's own motion and measurement models, a
  ``MultiMeasurementInitiator`` (GNN, a track after 3 detections) and a deleter after 3
  steps without a detection;
* mhtrack: :class:`mhtrack.stonesoup.MHTrackTracker`, the MHT with the known clutter
  density (tracker ``mht``), the same ``P_D``, and a single constant-velocity model of
  the simulator's process noise.

Each is scored by Stone Soup's own ``OSPAMetric`` (positions, ``c`` = 200 m, ``p`` = 1)
through its ``MultiManager``; the script prints each tracker's mean OSPA, its mean wall
time per step (the tracker alone; timings vary with the machine's load) and the ratio of
Stone Soup's step time to mhtrack's. It also prints mhtrack's own OSPA(2) and HOTA of all
three on the same tracks.

Run: ``python docs/examples/stonesoup.py [--steps N] [--seed S]`` (needs
``pip install -e ".[stonesoup]"``).
"""

# ruff: noqa: E402  (the imports follow the sys.path fix below)
from __future__ import annotations

import argparse
import datetime
import sys
import time
from pathlib import Path

# This file is called stonesoup.py: keep Python from importing it as the stonesoup package.
sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != Path(__file__).resolve().parent]

import numpy as np
from stonesoup.dataassociator.neighbour import GlobalNearestNeighbour, GNNWith2DAssignment
from stonesoup.dataassociator.probability import JPDA
from stonesoup.deleter.time import UpdateTimeStepsDeleter
from stonesoup.hypothesiser.distance import DistanceHypothesiser
from stonesoup.hypothesiser.probability import PDAHypothesiser
from stonesoup.initiator.simple import MultiMeasurementInitiator
from stonesoup.measures import Euclidean, Mahalanobis
from stonesoup.metricgenerator.manager import MultiManager
from stonesoup.metricgenerator.ospametric import OSPAMetric
from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.transition.linear import (
    CombinedLinearGaussianTransitionModel,
    ConstantVelocity,
)
from stonesoup.predictor.kalman import KalmanPredictor
from stonesoup.simulator.simple import MultiTargetGroundTruthSimulator, SimpleDetectionSimulator
from stonesoup.tracker.simple import MultiTargetMixtureTracker, MultiTargetTracker
from stonesoup.types.state import GaussianState
from stonesoup.updater.kalman import KalmanUpdater

from mhtrack.metrics import hota, ospa2_per_scan
from mhtrack.mht import MHTConfig
from mhtrack.stonesoup import MHTrackTracker, ground_truth_to_table, tracks_to_table

START = datetime.datetime(2024, 1, 1)
DT = 1.0  # s between steps
Q = 0.5  # m²/s³, the targets' process-noise intensity
SIGMA = 30.0  # m, position noise
PD = 0.9
CLUTTER_RATE = 20.0  # clutter detections per step
HALF_WIDTH = 2500.0  # m: detections in [-2500, 2500]²
SPEED = 15.0  # m/s, σ of a new target's velocity
OSPA_C, OSPA_P = 200.0, 1.0


def simulate(steps: int, seed: int):
    """Stone Soup's simulators: the recorded detector steps and the ground-truth paths."""
    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(Q)] * 2,
                                                       seed=seed)
    truth_sim = MultiTargetGroundTruthSimulator(
        transition_model=transition,
        initial_state=GaussianState([[0], [0], [0], [0]],
                                    np.diag([1000.0**2, SPEED**2, 1000.0**2, SPEED**2]),
                                    timestamp=START),
        timestep=datetime.timedelta(seconds=DT), number_steps=steps, birth_rate=0.08,
        death_probability=0.005, initial_number_targets=6, seed=seed)
    measurement = LinearGaussian(ndim_state=4, mapping=(0, 2),
                                 noise_covar=np.eye(2) * SIGMA**2, seed=seed + 1)
    det_sim = SimpleDetectionSimulator(
        groundtruth=truth_sim, measurement_model=measurement,
        meas_range=np.array([[-HALF_WIDTH, HALF_WIDTH]] * 2), detection_probability=PD,
        clutter_rate=CLUTTER_RATE, seed=seed)
    feed, paths = [], set()
    for t, dets in det_sim:
        feed.append((t, set(dets)))
        paths |= set(truth_sim.current[1])
    return feed, paths, transition, measurement, det_sim.clutter_spatial_density


def stonesoup_tracker(kind: str, feed, transition, measurement, clutter_density: float):
    """Stone Soup's GNN (``"gnn"``) or JPDA (``"jpda"``) multi-target tracker."""
    predictor = KalmanPredictor(transition)
    updater = KalmanUpdater(measurement)
    initiator = MultiMeasurementInitiator(
        prior_state=GaussianState(np.zeros((4, 1)), np.diag([0, SPEED**2, 0, SPEED**2])),
        measurement_model=measurement, deleter=UpdateTimeStepsDeleter(2),
        data_associator=GNNWith2DAssignment(
            DistanceHypothesiser(predictor, updater, Mahalanobis(), missed_distance=3)),
        updater=updater, min_points=3)
    deleter = UpdateTimeStepsDeleter(3)
    if kind == "gnn":
        associator = GlobalNearestNeighbour(
            DistanceHypothesiser(predictor, updater, Mahalanobis(), missed_distance=3))
        return MultiTargetTracker(initiator=initiator, deleter=deleter, detector=feed,
                                  data_associator=associator, updater=updater)
    associator = JPDA(PDAHypothesiser(predictor, updater, clutter_spatial_density=clutter_density,
                                      prob_detect=PD, prob_gate=0.999))
    return MultiTargetMixtureTracker(initiator=initiator, deleter=deleter, detector=feed,
                                     data_associator=associator, updater=updater)


def mhtrack_tracker(feed, clutter_density: float) -> MHTrackTracker:
    """mhtrack's MHT with the simulator's ``P_D``, clutter density and motion noise."""
    area = (2 * HALF_WIDTH) ** 2
    config = MHTConfig(p_detection=PD, sigma_w=SIGMA, sigma_v=float(np.sqrt(Q / DT)),
                       imm_sigma_v=0.0, v_max=4 * SPEED,
                       new_target_density=0.08 / area)
    return MHTrackTracker(detector=feed, tracker="mht", config=config,
                          clutter_density=clutter_density)


def run(tracker) -> tuple[set, float]:
    """All tracks the tracker reported and its mean wall time per step (s)."""
    tracks, wall, n = set(), 0.0, 0
    it = iter(tracker)
    while True:
        t0 = time.perf_counter()
        try:
            _, current = next(it)
        except StopIteration:
            break
        wall += time.perf_counter() - t0
        n += 1
        tracks |= current
    return tracks, wall / max(n, 1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    feed, paths, transition, measurement, kappa = simulate(args.steps, args.seed)
    n_dets = sum(len(d) for _, d in feed)
    print(f"{len(feed)} steps, {len(paths)} targets, {n_dets} detections "
          f"(clutter density {kappa:.2e} per m² per step)")
    trackers = {
        "Stone Soup GNN": stonesoup_tracker("gnn", feed, transition, measurement, kappa),
        "Stone Soup JPDA": stonesoup_tracker("jpda", feed, transition, measurement, kappa),
        "mhtrack MHT": mhtrack_tracker(feed, kappa),
    }
    results = {name: run(trk) for name, trk in trackers.items()}

    manager = MultiManager([OSPAMetric(c=OSPA_C, p=OSPA_P, measure=Euclidean((0, 2)),
                                       generator_name=name, tracks_key=name,
                                       truths_key="truth") for name in trackers])
    manager.add_data({"truth": paths, **{name: r[0] for name, r in results.items()}})
    metrics = manager.generate_metrics()
    times = [t for t, _ in feed]
    truth, _ = ground_truth_to_table(paths, START, times)
    print(f"\n{'tracker':16s} {'tracks':>6s} {'OSPA (Stone Soup)':>18s} {'OSPA(2) w=10':>13s} "
          f"{'HOTA':>6s} {'step (ms)':>10s}")
    ospa_mean = {}
    for name, (tracks, step_s) in results.items():
        values = [m.value for m in metrics[name]["OSPA distances"].value]
        ospa_mean[name] = float(np.mean(values))
        table = tracks_to_table(tracks, START, times)
        o2 = float(np.mean(ospa2_per_scan(table, truth, OSPA_C, OSPA_P, 10).distance))
        h = hota(table, truth, OSPA_C).hota
        print(f"{name:16s} {len(tracks):6d} {ospa_mean[name]:16.1f} m {o2:11.1f} m "
              f"{h:6.3f} {1e3 * step_s:10.2f}")
    mht, gnn = results["mhtrack MHT"][1], results["Stone Soup GNN"][1]
    jpda = results["Stone Soup JPDA"][1]
    print(f"\nstep time: Stone Soup GNN / mhtrack = {gnn / mht:.1f}x, "
          f"JPDA / mhtrack = {jpda / mht:.1f}x")
    better = ospa_mean["mhtrack MHT"] < min(ospa_mean["Stone Soup GNN"],
                                            ospa_mean["Stone Soup JPDA"])
    print(f"mhtrack's mean OSPA is {'the lowest' if better else 'NOT the lowest'} "
          "(Stone Soup's OSPAMetric)")


if __name__ == "__main__":
    main()
