"""Stone Soup detections → mhtrack plots against Stone Soup's own inverse functions, and
the table converters."""

import datetime
import importlib
import sys

import numpy as np
import pytest

pytest.importorskip("stonesoup", reason="Stone Soup not installed (pip install -e '.[stonesoup]')")

from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.measurement.nonlinear import (
    CartesianToBearingRange,
    CartesianToBearingRangeRate,
    CartesianToElevationBearingRange,
)
from stonesoup.types.detection import Clutter, Detection, TrueDetection
from stonesoup.types.groundtruth import GroundTruthPath, GroundTruthState
from stonesoup.types.state import State

from mhtrack.records import TrackTable
from mhtrack.stonesoup import (
    detections_to_plots,
    detections_to_xy,
    ground_truth_to_table,
    table_to_tracks,
    tracks_to_table,
)

T0 = datetime.datetime(2024, 1, 1)


def _inverse_jacobian(model, sv, idx, h=1e-6):
    """Central differences of Stone Soup's inverse_function (the (x, y) rows)."""
    cols = []
    for j in range(len(sv)):
        e = np.zeros((len(sv), 1))
        e[j] = h * max(1.0, abs(float(sv[j, 0])))
        plus = model.inverse_function(Detection(sv + e, measurement_model=model))
        minus = model.inverse_function(Detection(sv - e, measurement_model=model))
        cols.append((np.asarray(plus, float)[idx, 0] - np.asarray(minus, float)[idx, 0])
                    / (2 * e[j, 0]))
    return np.column_stack(cols)


def _target_states(rng, n, ndim):
    x = np.zeros((ndim, n))
    x[0], x[2] = rng.uniform(-40e3, 40e3, (2, n))
    if ndim == 6:
        x[4] = rng.uniform(500, 9000, n)
    return x


def test_bearing_range_matches_stonesoup_inverse_function():
    rng = np.random.default_rng(1)
    model = CartesianToBearingRange(
        ndim_state=4, mapping=(0, 2), noise_covar=np.diag([np.radians(0.2) ** 2, 40.0**2]),
        translation_offset=np.array([[1500.0], [-800.0]]),
        rotation_offset=np.array([[0.0], [0.0], [0.4]]))
    dets = [Detection(model.function(State(s.reshape(4, 1)), noise=True), timestamp=T0,
                      measurement_model=model) for s in _target_states(rng, 25, 4).T]
    z, R = detections_to_xy(dets)
    for det, zi, Ri in zip(dets, z, R, strict=True):
        ref = np.asarray(model.inverse_function(det), float)[(0, 2), 0]
        assert np.abs(zi - ref).max() < 1e-6  # metres
        J = _inverse_jacobian(model, np.asarray(det.state_vector, float), (0, 2))
        np.testing.assert_allclose(Ri, J @ model.covar() @ J.T, rtol=1e-5)


def test_elevation_bearing_range_matches_stonesoup_inverse_function():
    rng = np.random.default_rng(2)
    model = CartesianToElevationBearingRange(
        ndim_state=6, mapping=(0, 2, 4),
        noise_covar=np.diag([np.radians(0.5) ** 2, np.radians(0.2) ** 2, 30.0**2]),
        translation_offset=np.array([[200.0], [-300.0], [50.0]]),
        rotation_offset=np.array([[0.05], [-0.1], [1.2]]))
    dets = [Detection(model.function(State(s.reshape(6, 1)), noise=True), timestamp=T0,
                      measurement_model=model) for s in _target_states(rng, 25, 6).T]
    z, R = detections_to_xy(dets)
    for det, zi, Ri in zip(dets, z, R, strict=True):
        ref = np.asarray(model.inverse_function(det), float)[(0, 2), 0]
        assert np.abs(zi - ref).max() < 1e-6
        J = _inverse_jacobian(model, np.asarray(det.state_vector, float), (0, 2))
        np.testing.assert_allclose(Ri, J @ model.covar() @ J.T, rtol=1e-5)


def test_linear_gaussian_mapping_order_and_3d():
    R3 = np.array([[100.0, 5.0, 1.0], [5.0, 400.0, 2.0], [1.0, 2.0, 900.0]])
    swapped = LinearGaussian(ndim_state=4, mapping=(2, 0), noise_covar=R3[:2, :2])
    three = LinearGaussian(ndim_state=6, mapping=(0, 2, 4), noise_covar=R3)
    dets = [Detection(np.array([[7.0], [3.0]]), measurement_model=swapped),
            Detection(np.array([[1.0], [2.0], [3.0]]), measurement_model=three)]
    z, R = detections_to_xy(dets)
    np.testing.assert_array_equal(z, [[3.0, 7.0], [1.0, 2.0]])  # (x, y)
    np.testing.assert_array_equal(R[0], [[400.0, 5.0], [5.0, 100.0]])
    np.testing.assert_array_equal(R[1], R3[:2, :2])


def test_unsupported_or_missing_model_is_one_clear_error():
    rr = CartesianToBearingRangeRate(ndim_state=6, mapping=(0, 2, 4), velocity_mapping=(1, 3, 5),
                                     noise_covar=np.eye(3))
    with pytest.raises(ValueError, match="not supported"):
        detections_to_xy([Detection(np.zeros((3, 1)), measurement_model=rr)])
    with pytest.raises(ValueError, match="no measurement model"):
        detections_to_xy([Detection(np.zeros((2, 1)), timestamp=T0)])
    default = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2))
    z, _ = detections_to_xy([Detection(np.ones((2, 1)))], measurement_model=default)
    assert z.tolist() == [[1.0, 1.0]]


def test_detections_to_plots_and_truth_with_origins():
    model = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2) * 25.0)
    path = GroundTruthPath([GroundTruthState([[10.0 * k], [10.0], [0.0], [0.0]],
                                             timestamp=T0 + datetime.timedelta(seconds=2 * k))
                            for k in range(3)])
    feed = []
    for k, s in enumerate(path.states):
        dets = {TrueDetection(model.function(s), timestamp=s.timestamp, measurement_model=model,
                              groundtruth_path=path),
                Clutter(np.array([[500.0 + k], [500.0]]), timestamp=s.timestamp,
                        measurement_model=model)}
        feed.append((s.timestamp, dets))
    feed.append((T0 + datetime.timedelta(seconds=6), set()))  # an empty step
    truth, ids = ground_truth_to_table([path], T0, [t for t, _ in feed])
    assert ids == {path: 0}
    assert truth.scan.tolist() == [0, 1, 2] and truth.time.tolist() == [0.0, 2.0, 4.0]
    plots = detections_to_plots(feed, truth_ids=ids)
    assert plots.all_scan_times()[0].tolist() == [0, 1, 2, 3]
    assert plots.all_scan_times()[1].tolist() == [0.0, 2.0, 4.0, 6.0]
    assert sorted(plots.origin.tolist()) == [-1, -1, -1, 0, 0, 0]
    target = plots.origin == 0
    np.testing.assert_allclose(plots.x[target], [0.0, 10.0, 20.0])
    np.testing.assert_allclose(plots.R, np.broadcast_to(np.eye(2) * 25.0, (6, 2, 2)))
    # without the ids, no origin column
    assert detections_to_plots(feed).origin is None


def test_tracks_round_trip():
    P = np.stack([np.diag([1.0, 2.0, 3.0, 4.0]) * (i + 1) for i in range(4)])
    table = TrackTable(np.array([0, 0, 1, 2]), np.array([0.0, 0.0, 1.0, 2.0]),
                       np.array([5, 9, 5, 5]), np.array([1.0, 2.0, 3.0, 4.0]),
                       np.array([10.0, 20.0, 30.0, 40.0]), np.array([0.1, 0.2, 0.3, 0.4]),
                       np.array([-0.1, -0.2, -0.3, -0.4]), np.full(4, -1), P=P)
    tracks = table_to_tracks(table, T0)
    by_id = {t.id: t for t in tracks}
    assert set(by_id) == {"mhtrack-5", "mhtrack-9"}
    s = by_id["mhtrack-5"].states[1]
    np.testing.assert_array_equal(np.asarray(s.state_vector).ravel(), [3.0, 0.3, 30.0, -0.3])
    np.testing.assert_array_equal(np.asarray(s.covar), P[2])
    back = tracks_to_table(tracks, T0, [T0 + datetime.timedelta(seconds=k) for k in range(3)])
    order = np.lexsort((table.track_id, table.scan))
    np.testing.assert_array_equal(back.x, table.x[order])
    np.testing.assert_array_equal(back.vy, table.vy[order])
    assert back.scan.tolist() == table.scan[order].tolist()


def test_missing_stonesoup_gives_one_line(monkeypatch):
    for name in [m for m in sys.modules if m.startswith("mhtrack.stonesoup")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "stonesoup", None)
    with pytest.raises(ImportError, match=r'pip install "mhtrack\[stonesoup\]"') as err:
        importlib.import_module("mhtrack.stonesoup")
    assert "\n" not in str(err.value)
