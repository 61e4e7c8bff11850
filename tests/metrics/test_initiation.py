"""Initiation and clustering metrics on hand-worked examples."""

import math

import numpy as np
import pytest

from mhtrack.metrics.initiation import (
    cluster_purity,
    clustering_metrics,
    fused_plot_errors,
    initiable_targets,
    initiation_metrics,
    track_targets,
)


def test_track_targets():
    origins = np.array([
        [1, 1, 1, -1],   # 3 plots of target 1: true
        [1, 2, 1, -2],   # 2 + 1: false
        [-1, -1, 2, 2],  # false
        [3, 3, 3, 3],    # true
        [-2, 4, 4, 4],   # 3 plots, missed scan: true
    ])
    np.testing.assert_array_equal(track_targets(origins), [1, -1, -1, 3, 4])
    np.testing.assert_array_equal(track_targets(origins, min_plots=4), [-1, -1, -1, 3, -1])
    assert track_targets(np.zeros((0, 4), int)).shape == (0,)


def test_initiable_targets():
    ids, seen = np.array([1, 2, 3, 7]), np.array([4, 2, 3, 1])
    np.testing.assert_array_equal(initiable_targets(ids, seen), [1, 3])


def test_initiation_metrics_hand_example():
    # window 0: targets {1, 2, 3}; tracks true for 1, 1 (duplicate), 3 and one false
    # window 1: target {1}; two false tracks
    m = initiation_metrics(
        [np.array([1, -1, 1, 3]), np.array([-1, -1])],
        [np.array([1, 2, 3]), np.array([1])],
        n_runs=2,
        window_seconds=[0.002, 0.004],
    )
    assert m.p_true == pytest.approx(2 / 4)      # {1, 3} of 3, none of 1
    # P2's reading: 3 false against 2 found targets (the duplicate on 1 counts once)
    assert m.p_false == pytest.approx(3 / 5)
    assert m.p_false_tracks == pytest.approx(3 / 6)  # every track counted
    assert m.false_per_run == pytest.approx(1.5)
    assert m.false_per_window == pytest.approx(1.5)
    assert m.tracks_per_run == pytest.approx(3.0)
    assert m.duplicates_per_run == pytest.approx(0.5)
    assert m.t_window == pytest.approx(0.003)
    assert (m.n_windows, m.n_targets, m.n_tracks) == (2, 4, 6)
    assert m.to_dict()["p_true"] == pytest.approx(0.5)


def test_initiation_metrics_without_tracks():
    m = initiation_metrics([np.zeros(0, int)], [np.array([5])], n_runs=1)
    assert m.p_true == 0.0
    assert math.isnan(m.p_false) and math.isnan(m.t_window)
    with pytest.raises(ValueError, match="windows"):
        initiation_metrics([np.zeros(0, int)], [], n_runs=1)


def test_fused_plot_errors_use_the_optimal_assignment():
    fused = np.array([[0.0, 0.0], [10.0, 0.0], [500.0, 500.0]])
    truth = np.array([[9.0, 0.0], [1.0, 0.0]])
    # greedy nearest would also pair these; the optimum is 1 + 1 (not 9 + 9)
    np.testing.assert_allclose(np.sort(fused_plot_errors(fused, truth)), [1.0, 1.0])
    # a crossing case where greedy fails: truth (0) is nearest to fused (0.9)…
    fused2 = np.array([[0.9, 0.0], [3.0, 0.0]])
    truth2 = np.array([[0.0, 0.0], [1.0, 0.0]])
    assert fused_plot_errors(fused2, truth2).sum() == pytest.approx(0.9 + 2.0)


def test_cluster_purity():
    labels = np.array([0, 0, 1, 1, 2, 3, 3])
    origin = np.array([1, 1, 1, -1, -1, 2, 3])
    # cluster 0 pure, 1 target+clutter, 2 clutter only (not counted), 3 two targets
    assert cluster_purity(labels, origin) == (1, 3)


def test_clustering_metrics():
    m = clustering_metrics([10, 11, 10], [10, 10, 9], [np.array([1.0, 3.0]), np.array([2.0])],
                           [(9, 10), (10, 10), (9, 9)], [0.001, 0.002, 0.003])
    assert m.k_correct_rate == pytest.approx(1 / 3)
    assert m.mean_clusters == pytest.approx(31 / 3)
    assert m.fused_error_mean == pytest.approx(2.0)
    assert m.purity == pytest.approx(28 / 29)
    assert m.t_scan == pytest.approx(0.002)
    assert m.n_scans == 3
