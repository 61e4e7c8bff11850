"""OSPA(2) against a hand-worked example, against Stone Soup's OSPA where they coincide
(a window of one scan), and its metric properties."""

import datetime
import math

import numpy as np
import pytest

from mhtrack.metrics import ospa_per_scan
from mhtrack.metrics.ospa2 import ospa2_per_scan


def _hand_case(make_truth, make_tracks):
    # target A at (0, 0) at scans 0, 1, 2; track 1 at (0, 30) at scans 0, 1; track 2 at
    # (0, 40) at scan 2.
    truth = make_truth([(k, 1, 0.0, 0.0) for k in range(3)])
    tracks = make_tracks([(0, 1, 0.0, 30.0), (1, 1, 0.0, 30.0), (2, 2, 0.0, 40.0)])
    return tracks, truth


def test_hand_worked_window_of_three(make_truth, make_tracks):
    tracks, truth = _hand_case(make_truth, make_tracks)
    c = 100.0
    # scan 2, window {0, 1, 2}: d̃(A, T1) = (30 + 30 + c)/3 = 160/3 (T1 missing at scan 2
    # counts c); d̃(A, T2) = (c + c + 40)/3 = 80. One truth, two tracks: A–T1 assigned,
    # the second track is a cardinality error c.
    r1 = ospa2_per_scan(tracks, truth, c, 1.0, window=3)
    assert r1.scan.tolist() == [0, 1, 2]
    # scans 0 and 1: windows {0} and {0, 1} hold A and T1 only, 30 m at each scan
    assert r1.distance[:2] == pytest.approx([30.0, 30.0])
    # p = 1: (160/3 + 100)/2 = 76.67 = 26.67 (localisation) + 50 (cardinality)
    assert r1.distance[2] == pytest.approx((160 / 3 + 100) / 2)
    assert r1.localisation[2] == pytest.approx(160 / 6)
    assert r1.cardinality[2] == pytest.approx(50.0)
    r2 = ospa2_per_scan(tracks, truth, c, 2.0, window=3)
    assert r2.distance[2] == pytest.approx(math.sqrt(((160 / 3) ** 2 + 100**2) / 2))
    assert r2.distance[2] ** 2 == pytest.approx(r2.localisation[2] ** 2
                                                + r2.cardinality[2] ** 2)


def test_window_counts_scan_indices_not_rows(make_truth, make_tracks):
    # evaluated scans 0, 1, 5: at scan 5 a window of 3 holds scans 3..5, i.e. only scan 5
    truth = make_truth([(0, 1, 0.0, 0.0), (1, 1, 0.0, 0.0), (5, 1, 0.0, 0.0)])
    tracks = make_tracks([(0, 1, 0.0, 10.0), (1, 1, 0.0, 10.0), (5, 2, 0.0, 20.0)])
    r = ospa2_per_scan(tracks, truth, 100.0, 1.0, window=3)
    assert r.distance.tolist() == pytest.approx([10.0, 10.0, 20.0])


def test_window_one_is_ospa(random_run):
    truth, tracks = random_run(4)
    for p in (1.0, 2.0):
        a = ospa2_per_scan(tracks, truth, 300.0, p, window=1)
        b = ospa_per_scan(tracks, truth, 300.0, p)
        np.testing.assert_allclose(a.distance, b.distance, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(a.cardinality, b.cardinality, rtol=1e-12, atol=1e-9)


def test_window_one_equals_stonesoup_ospa(random_run):
    ospametric = pytest.importorskip("stonesoup.metricgenerator.ospametric")
    manager = pytest.importorskip("stonesoup.metricgenerator.manager")
    types = pytest.importorskip("stonesoup.types.groundtruth")
    track_t = pytest.importorskip("stonesoup.types.track")
    state_t = pytest.importorskip("stonesoup.types.state")
    truth, tracks = random_run(5)
    t0 = datetime.datetime(2024, 1, 1)

    def paths(ids, scan, pos, make_path, make_state):
        out = []
        for i in np.unique(ids):
            rows = np.flatnonzero(ids == i)
            out.append(make_path([make_state(pos[r].reshape(2, 1), timestamp=t0
                                             + datetime.timedelta(seconds=int(scan[r])))
                                  for r in rows]))
        return out

    gt = paths(truth.target_id, truth.scan, truth.positions, types.GroundTruthPath,
               types.GroundTruthState)
    trk = paths(tracks.track_id, tracks.scan, tracks.positions, track_t.Track,
                state_t.State)
    # p = 1: Stone Soup's assignment (on min(d, c)) is the optimal one (see test_ospa.py)
    gen = ospametric.OSPAMetric(c=300.0, p=1.0)
    mm = manager.MultiManager([gen])
    mm.add_data({"groundtruth_paths": gt, "tracks": trk})
    ss = mm.generate_metrics()["ospa_generator"]["OSPA distances"].value
    ss_t = np.array([(m.timestamp - t0).total_seconds() for m in ss])
    ss_v = np.array([m.value for m in ss])
    ours = ospa2_per_scan(tracks, truth, 300.0, 1.0, window=1)
    assert ss_t.tolist() == ours.scan.astype(float).tolist()
    np.testing.assert_allclose(ours.distance, ss_v, rtol=1e-10, atol=1e-9)


def test_bounded_and_symmetric(random_run):
    truth, tracks = random_run(6)
    r = ospa2_per_scan(tracks, truth, 250.0, 2.0, window=5)
    assert np.all((r.distance >= 0) & (r.distance <= 250.0 + 1e-9))
    # swap the roles: tracks as truth and truth as tracks
    from mhtrack.records import TrackTable, TruthTable

    as_truth = TruthTable(tracks.scan, tracks.time, tracks.track_id, tracks.x, tracks.y,
                          tracks.vx, tracks.vy)
    as_tracks = TrackTable(truth.scan, truth.time, truth.target_id, truth.x, truth.y,
                           truth.vx, truth.vy, np.full(len(truth), -1))
    s = ospa2_per_scan(as_tracks, as_truth, 250.0, 2.0, window=5)
    np.testing.assert_allclose(r.distance, s.distance, rtol=1e-12)
    # identical sets: zero
    z = ospa2_per_scan(as_tracks, truth, 250.0, 2.0, window=5)
    assert np.all(z.distance == 0.0)


def test_identity_swap_costs_more_with_a_longer_window(make_truth, make_tracks):
    # two targets 1 km apart; their tracks swap ids at scan 5 (positions stay right).
    # Per-scan OSPA sees nothing; OSPA(2) over 4 scans does, at the scans after the swap.
    truth = make_truth([(k, i, 1000.0 * i, 0.0) for k in range(10) for i in range(2)])
    tracks = make_tracks([(k, i if k < 5 else 1 - i, 1000.0 * i, 0.0)
                          for k in range(10) for i in range(2)])
    r1 = ospa2_per_scan(tracks, truth, 500.0, 1.0, window=1)
    r4 = ospa2_per_scan(tracks, truth, 500.0, 1.0, window=4)
    assert np.all(r1.distance == 0.0)
    assert np.all(r4.distance[:5] == 0.0)
    # scan 5, window {2..5}: each track is right for 3 scans and 500 (c) off for 1 →
    # d̃ = 125 per pair, both assignments equal: OSPA(2) = 125
    assert r4.distance[5] == pytest.approx(125.0)
    # scan 6, window {3..6}: two scans right, two off for either pairing → 250; from
    # scan 8 on (window {5..8}) the swapped ids fit throughout → 0
    assert r4.distance[6] == pytest.approx(250.0)
    assert r4.distance[8:] == pytest.approx([0.0, 0.0])


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, "3"])
def test_window_must_be_positive_integer(random_run, bad):
    truth, tracks = random_run(1)
    with pytest.raises(ValueError, match="window"):
        ospa2_per_scan(tracks, truth, 100.0, 1.0, window=bad)


def test_in_evaluate(random_run):
    from mhtrack.metrics import evaluate

    truth, tracks = random_run(2)
    ev = evaluate(tracks, truth, cutoff=300.0, order=2.0, ospa2_window=4)
    direct = ospa2_per_scan(tracks, truth, 300.0, 2.0, window=4)
    np.testing.assert_array_equal(ev.ospa2.distance, direct.distance)
    d = ev.to_dict()
    assert d["ospa2_window"] == 4
    assert d["ospa2"] == direct.distance.tolist()
    assert d["ospa2_mean"] == pytest.approx(float(np.mean(direct.distance)))
    assert "OSPA(2) mean (window 4 scans)" in ev.to_table()
    with pytest.raises(ValueError, match="ospa2_window"):
        evaluate(tracks, truth, ospa2_window=0)
