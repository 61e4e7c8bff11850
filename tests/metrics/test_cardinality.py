"""Cardinality per scan against hand counts."""

import pytest

from mhtrack.metrics import cardinality_per_scan


def test_counts_and_error(make_truth, make_tracks):
    # scan 0: 2 truths, 3 tracks; 1: 1 truth, 0 tracks; 3: 0 truths, 1 track
    truth = make_truth([(0, 1, 0, 0), (0, 2, 5, 5), (1, 1, 0, 0)])
    tracks = make_tracks([(0, 10, 0, 0), (0, 11, 1, 1), (0, 12, 2, 2), (3, 10, 0, 0)])
    r = cardinality_per_scan(tracks, truth, scans=[2, 4])
    assert r.scan.tolist() == [0, 1, 2, 3, 4]
    assert r.n_true.tolist() == [2, 1, 0, 0, 0]
    assert r.n_tracks.tolist() == [3, 0, 0, 1, 0]
    assert r.error.tolist() == [1, 1, 0, 1, 0]


def test_row_order_does_not_matter(make_truth, make_tracks):
    from dataclasses import replace

    truth = make_truth([(0, 1, 0, 0), (1, 2, 5, 5), (1, 1, 0, 0)])
    tracks = make_tracks([(1, 10, 0, 0), (0, 11, 1, 1), (1, 12, 2, 2)])
    rev = {
        f: getattr(tracks, f)[::-1]
        for f in ("scan", "time", "track_id", "x", "y", "vx", "vy", "plot")
    }
    r = cardinality_per_scan(replace(tracks, **rev), truth)
    assert r.n_tracks.tolist() == [1, 2]
    assert r.n_true.tolist() == [1, 2]


def test_repeated_id_in_a_scan_is_rejected(make_truth, make_tracks):
    truth = make_truth([(0, 1, 0, 0)])
    tracks = make_tracks([(0, 10, 0, 0), (0, 10, 1, 1)])
    with pytest.raises(ValueError, match="tracks has a repeated"):
        cardinality_per_scan(tracks, truth)
