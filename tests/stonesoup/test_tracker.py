"""MHTrackTracker: Stone Soup tracks out of a Stone Soup simulation, the same tracks as
mhtrack's own run, and Stone Soup's OSPA on them equal to mhtrack's."""

import datetime

import numpy as np
import pytest

pytest.importorskip("stonesoup", reason="Stone Soup not installed (pip install -e '.[stonesoup]')")

from stonesoup.measures import Euclidean
from stonesoup.metricgenerator.manager import MultiManager
from stonesoup.metricgenerator.ospametric import OSPAMetric
from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.measurement.nonlinear import CartesianToBearingRange
from stonesoup.models.transition.linear import (
    CombinedLinearGaussianTransitionModel,
    ConstantVelocity,
)
from stonesoup.simulator.simple import (
    MultiTargetGroundTruthSimulator,
    SimpleDetectionSimulator,
)
from stonesoup.tracker.base import Tracker
from stonesoup.types.detection import Detection
from stonesoup.types.prediction import GaussianStatePrediction
from stonesoup.types.state import GaussianState, State
from stonesoup.types.track import Track
from stonesoup.types.update import GaussianStateUpdate

from mhtrack.build import make_tracker
from mhtrack.metrics import ospa_per_scan
from mhtrack.mht import MHTConfig
from mhtrack.stonesoup import (
    MHTrackTracker,
    detections_to_plots,
    ground_truth_to_table,
    tracks_to_table,
)

T0 = datetime.datetime(2024, 1, 1)
CONFIG = MHTConfig(p_detection=0.9, sigma_w=20.0, sigma_v=1.0, imm_sigma_v=0.0, v_max=60.0,
                   new_target_density=1e-8)
KAPPA = 4.0 / 2000.0**2


@pytest.fixture(scope="module")
def scene():
    """A small Stone Soup simulation: 4 targets, P_D 0.9, σ 20 m, 4 clutter per step."""
    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(0.5)] * 2, seed=3)
    truth_sim = MultiTargetGroundTruthSimulator(
        transition_model=transition,
        initial_state=GaussianState([[0], [0], [0], [0]], np.diag([500.0**2, 10.0**2] * 2),
                                    timestamp=T0),
        timestep=datetime.timedelta(seconds=1), number_steps=30, birth_rate=0.0,
        death_probability=0.0, initial_number_targets=4, seed=3)
    model = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2) * 400.0,
                           seed=4)
    det_sim = SimpleDetectionSimulator(
        groundtruth=truth_sim, measurement_model=model,
        meas_range=np.array([[-1000.0, 1000.0]] * 2), detection_probability=0.9,
        clutter_rate=4.0, seed=3)
    feed, paths = [], set()
    for t, dets in det_sim:
        feed.append((t, set(dets)))
        paths |= set(truth_sim.current[1])
    return feed, paths


def _run(feed):
    trk = MHTrackTracker(detector=feed, tracker="mht", config=CONFIG, clutter_density=KAPPA)
    steps = list(trk)
    return trk, steps


def test_yields_stonesoup_tracks(scene):
    feed, _ = scene
    trk = MHTrackTracker(detector=feed, tracker="mht", config=CONFIG, clutter_density=KAPPA)
    assert isinstance(trk, Tracker)
    seen: dict[str, Track] = {}
    times = []
    for t, tracks in trk:  # checked at each step, as a Stone Soup user reads them
        times.append(t)
        assert tracks == trk.tracks
        for track in tracks:
            assert isinstance(track, Track)
            assert seen.setdefault(track.id, track) is track  # one object per track id
            state = track.state
            assert state.timestamp == t
            assert isinstance(state, GaussianStateUpdate | GaussianStatePrediction)
            assert state.state_vector.shape == (4, 1) and state.covar.shape == (4, 4)
            if isinstance(state, GaussianStateUpdate):
                assert state.hypothesis.measurement in feed[[s for s, _ in feed].index(t)][1]
    assert times == [t for t, _ in feed]
    assert 3 <= len(trk.all_tracks) <= 6
    # states in Stone Soup's order (x, vx, y, vy), equal to mhtrack's own table
    table = trk.table
    for track in trk.all_tracks:
        tid = int(track.id.removeprefix("mhtrack-"))
        rows = np.flatnonzero(table.track_id == tid)
        means = np.hstack([np.asarray(s.state_vector, float) for s in track.states])
        np.testing.assert_array_equal(means, np.vstack(
            (table.x[rows], table.vx[rows], table.y[rows], table.vy[rows])))
        assert [s.timestamp for s in track.states] == sorted(s.timestamp for s in track.states)


def test_same_tracks_as_mhtrack_on_the_plot_table(scene):
    feed, _ = scene
    trk, _ = _run(feed)
    plots = detections_to_plots(feed)
    direct = make_tracker("mht", CONFIG, clutter_density=KAPPA).run(plots)
    ours = trk.table
    for f in ("scan", "track_id", "x", "y", "vx", "vy", "plot"):
        np.testing.assert_array_equal(getattr(ours, f), getattr(direct, f), err_msg=f)


@pytest.mark.parametrize("p", [1.0, 2.0])
def test_stonesoup_ospa_equals_mhtrack_ospa(scene, p):
    feed, paths = scene
    trk, _ = _run(feed)
    c = 100.0
    manager = MultiManager([OSPAMetric(c=c, p=p, measure=Euclidean((0, 2)))])
    manager.add_data({"groundtruth_paths": paths, "tracks": trk.all_tracks})
    values = manager.generate_metrics()["ospa_generator"]["OSPA distances"].value
    ss = np.array([m.value for m in values])
    ss_t = [m.timestamp for m in values]
    times = [t for t, _ in feed]
    truth, _ = ground_truth_to_table(paths, T0, times)
    ours = ospa_per_scan(trk.table, truth, c, p)
    assert [times[k] for k in ours.scan] == ss_t
    # p = 1 exactly; p = 2 within 1 mm: Stone Soup assigns on min(d, c), not its p-th
    # power (tests/metrics/test_ospa.py), which only matters when two pairings compete
    np.testing.assert_allclose(ours.distance, ss, rtol=0, atol=1e-9 if p == 1 else 1e-3)
    # and the converter back from Stone Soup tracks gives the same numbers
    again = ospa_per_scan(tracks_to_table(trk.all_tracks, T0, times), truth, c, p)
    np.testing.assert_allclose(again.distance, ours.distance, rtol=0, atol=1e-9)


def test_bearing_range_sensors_with_their_own_timestamps():
    # two radars at different sites; each step holds one plot of one target from each,
    # 0.3 s apart: a timed frame (plots keep their own times)
    radars = [CartesianToBearingRange(ndim_state=4, mapping=(0, 2),
                                      noise_covar=np.diag([np.radians(0.3) ** 2, 25.0**2]),
                                      translation_offset=np.array([[x0], [y0]]), seed=5 + i)
              for i, (x0, y0) in enumerate([(-5000.0, 0.0), (0.0, -6000.0)])]
    feed = []
    for k in range(25):
        t = T0 + datetime.timedelta(seconds=2 * k)
        dets = set()
        for i, radar in enumerate(radars):
            ti = t - datetime.timedelta(seconds=0.3 * (1 - i))
            s = (ti - T0).total_seconds()
            truth = State([[100.0 + 20.0 * s], [20.0], [300.0 - 5.0 * s], [-5.0]], timestamp=ti)
            dets.add(Detection(radar.function(truth, noise=True), timestamp=ti,
                               measurement_model=radar))
        feed.append((t, dets))
    trk = MHTrackTracker(detector=feed, tracker="mht", config=CONFIG, clutter_density=1e-9)
    out = list(trk)
    assert len(trk.all_tracks) == 1
    track = next(iter(trk.all_tracks))
    last = track.state
    assert last.timestamp == out[-1][0]  # a frame's state is at its latest plot
    s = (last.timestamp - T0).total_seconds()
    x, y = float(last.state_vector[0, 0]), float(last.state_vector[2, 0])
    assert np.hypot(x - (100.0 + 20.0 * s), y - (300.0 - 5.0 * s)) < 60.0


def test_iterating_without_detector_is_an_error():
    with pytest.raises(AttributeError, match="detector"):
        iter(MHTrackTracker())


def test_siap_and_plotter_work_unchanged(scene):
    import matplotlib.pyplot as plt
    from stonesoup.dataassociator.tracktotrack import TrackToTruth
    from stonesoup.metricgenerator.tracktotruthmetrics import SIAPMetrics
    from stonesoup.plotter import Plotter

    feed, paths = scene
    trk, _ = _run(feed)
    siap = SIAPMetrics(position_measure=Euclidean((0, 2)), velocity_measure=Euclidean((1, 3)))
    manager = MultiManager([siap], associator=TrackToTruth(association_threshold=100))
    manager.add_data({"tracks": trk.all_tracks, "groundtruth_paths": paths})
    m = manager.generate_metrics()["siap_generator"]
    # every target tracked most of the time, by about one track, within σ-ish of the truth
    assert m["SIAP Completeness"].value > 0.8
    assert 1.0 <= m["SIAP Ambiguity"].value < 1.2
    assert m["SIAP Position Accuracy"].value < 40.0
    plotter = Plotter()
    plotter.plot_tracks(trk.all_tracks, [0, 2], uncertainty=True)
    assert len(plotter.ax.lines) >= len(trk.all_tracks)
    plt.close(plotter.fig)
