"""CLEAR-MOT against hand-worked scenarios and motmetrics."""

import math

import numpy as np
import pytest

from mhtrack.metrics import DEFAULT_MATCH_DISTANCE, clear_mot
from mhtrack.records import TrackTable, TruthTable

# ---------------------------------------------------------------- hand-worked scenarios


def test_switch_fragmentation_false_hand_worked(make_truth, make_tracks):
    # Targets 1 at (0,0) and 2 at (1000,0), scans 0–5 (GT = 12).
    # Track 10 follows target 1 at 10 m, absent at scan 2   → 1 miss, 1 fragmentation.
    # Track 20 follows target 2 at 20 m on scans 0–2, track 21 on 3–5 → 1 identity switch.
    # Track 99 far away at scan 4                          → 1 false positive.
    truth = make_truth([(k, t, x, 0) for k in range(6) for t, x in ((1, 0), (2, 1000))])
    rows = [(k, 10, 0, 10) for k in (0, 1, 3, 4, 5)]
    rows += [(k, 20 if k < 3 else 21, 1000, 20) for k in range(6)]
    rows += [(4, 99, 5000, 5000)]
    r = clear_mot(make_tracks(rows), truth)
    assert (r.n_truth, r.n_matches, r.n_misses, r.n_false) == (12, 11, 1, 1)
    assert (r.id_switches, r.fragmentations) == (1, 1)
    assert r.mota == pytest.approx(1 - (1 + 1 + 1) / 12)  # 0.75
    assert r.motp == pytest.approx((5 * 10 + 6 * 20) / 11)
    m = r.matching
    assert m.scan.tolist() == [0, 0, 1, 1, 2, 3, 3, 4, 4, 5, 5]
    assert m.track_id[m.target_id == 2].tolist() == [20, 20, 20, 21, 21, 21]
    assert m.is_switch.tolist() == [False] * 6 + [True] + [False] * 4
    assert r.match_distance == DEFAULT_MATCH_DISTANCE


def test_kept_correspondence_beats_a_closer_track(make_truth, make_tracks):
    # Scan 0: target at origin, track A (id 1) 50 m away, B (id 2) 300 m away → A.
    # Scan 1: A 100 m away, B 10 m away: A is kept (within d_match = 500) → no switch.
    # Scan 2: A 600 m away (beyond d_match), B 10 m → B is matched: one switch.
    truth = make_truth([(k, 7, 0, 0) for k in range(3)])
    tracks = make_tracks(
        [
            (0, 1, 50, 0),
            (0, 2, 300, 0),
            (1, 1, 100, 0),
            (1, 2, 10, 0),
            (2, 1, 600, 0),
            (2, 2, 10, 0),
        ]
    )
    r = clear_mot(tracks, truth, match_distance=500)
    assert r.matching.track_id.tolist() == [1, 1, 2]
    assert r.matching.distance.tolist() == [50, 100, 10]
    assert r.id_switches == 1
    assert r.n_false == 3


def test_memory_survives_a_missed_scan(make_truth, make_tracks):
    # Scan 0: target matched to A. Scan 1: no track at all (miss). Scan 2: A at 200 m and
    # B at 10 m: the remembered correspondence to A is kept (motmetrics' behaviour), no
    # switch. Fragmentation: matched, missed, matched → 1.
    truth = make_truth([(k, 7, 0, 0) for k in range(3)])
    tracks = make_tracks([(0, 1, 5, 0), (2, 1, 200, 0), (2, 2, 10, 0)])
    r = clear_mot(tracks, truth, match_distance=500)
    assert r.matching.track_id.tolist() == [1, 1]
    assert (r.id_switches, r.fragmentations, r.n_misses, r.n_false) == (0, 1, 1, 1)


def test_two_truths_remembering_one_track(make_truth, make_tracks):
    # Scan 0: target 1 ↔ track 5. Scan 1: track 5 is next to target 2 only (> d_match from
    # target 1) → 2 ↔ 5 (target 2 had no earlier match: not a switch). Scan 2: both targets
    # within d_match of track 5 and both remember it: the smaller target id (1) keeps it.
    truth = make_truth([(0, 1, 0, 0), (1, 1, 0, 0), (1, 2, 900, 0), (2, 1, 0, 0), (2, 2, 200, 0)])
    tracks = make_tracks([(0, 5, 0, 0), (1, 5, 900, 0), (2, 5, 150, 0)])
    r = clear_mot(tracks, truth, match_distance=300)
    assert list(zip(r.matching.scan.tolist(), r.matching.target_id.tolist(), strict=True)) == [
        (0, 1),
        (1, 2),
        (2, 1),
    ]
    assert r.id_switches == 0


def test_fragmentation_conventions(make_truth, make_tracks):
    # target 1: present 0,1,3 (absent at 2) and tracked whenever present → no fragmentation
    # target 2: tracked 0,1 then missed 2,3 (never re-acquired) → no fragmentation
    # target 3: tracked 0, missed 1, tracked 2, missed 3, tracked 4 → 2 fragmentations
    truth = make_truth(
        [(k, 1, 0, 0) for k in (0, 1, 3)]
        + [(k, 2, 5000, 0) for k in range(4)]
        + [(k, 3, 0, 5000) for k in range(5)]
    )
    tracks = make_tracks(
        [(k, 11, 0, 0) for k in (0, 1, 3)]
        + [(k, 12, 5000, 0) for k in (0, 1)]
        + [(k, 13, 0, 5000) for k in (0, 2, 4)]
    )
    r = clear_mot(tracks, truth)
    assert r.fragmentations == 2
    assert r.id_switches == 0


def test_empty_inputs():
    r = clear_mot(TrackTable.empty(), TruthTable(*([np.zeros(0)] * 7)))
    assert math.isnan(r.mota) and math.isnan(r.motp)
    assert (r.n_truth, r.n_matches, r.id_switches, r.fragmentations) == (0, 0, 0, 0)
    assert len(r.matching) == 0


def test_no_tracks(make_truth):
    r = clear_mot(TrackTable.empty(), make_truth([(0, 1, 0, 0), (1, 1, 0, 0)]))
    assert r.mota == 0.0
    assert math.isnan(r.motp)
    assert r.n_misses == 2


@pytest.mark.parametrize("bad", [-1.0, 0.0, float("nan"), "x"])
def test_invalid_match_distance(bad, make_truth):
    with pytest.raises(ValueError, match="match_distance"):
        clear_mot(TrackTable.empty(), make_truth([(0, 1, 0, 0)]), match_distance=bad)


# ---------------------------------------------------------------- motmetrics reference


def _motmetrics(truth, tracks, d_match):
    """motmetrics on the same data: Euclidean distances, NaN beyond ``d_match``."""
    mm = pytest.importorskip("motmetrics")
    acc = mm.MOTAccumulator(auto_id=False)
    for s in np.union1d(truth.scan, tracks.scan):
        ti, ki = truth.scan == s, tracks.scan == s
        o, h = np.argsort(truth.target_id[ti]), np.argsort(tracks.track_id[ki])
        a, b = truth.positions[ti][o], tracks.positions[ki][h]
        dist = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=-1)
        dist[dist > d_match] = np.nan
        acc.update(truth.target_id[ti][o], tracks.track_id[ki][h], dist, frameid=int(s))
    metrics = [
        "mota",
        "motp",
        "num_switches",
        "num_fragmentations",
        "num_detections",
        "num_misses",
        "num_false_positives",
        "num_objects",
    ]
    return mm.metrics.create().compute(acc, metrics=metrics, return_dataframe=False)


def _compare(r, m):
    assert r.mota == pytest.approx(m["mota"], rel=1e-12)
    assert r.motp == pytest.approx(m["motp"], rel=1e-12)
    assert r.id_switches == m["num_switches"]
    assert r.fragmentations == m["num_fragmentations"]
    assert r.n_matches == m["num_detections"]
    assert (r.n_misses, r.n_false, r.n_truth) == (
        m["num_misses"],
        m["num_false_positives"],
        m["num_objects"],
    )


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("d_match", [200.0, 500.0])
def test_against_motmetrics_live(seed, d_match, random_run):
    truth, tracks = random_run(seed)
    r = clear_mot(tracks, truth, match_distance=d_match)
    assert r.id_switches > 0 and r.n_misses > 0 and r.n_false > 0  # scenario exercises all
    _compare(r, _motmetrics(truth, tracks, d_match))


def test_hand_scenarios_against_motmetrics_live(make_truth, make_tracks):
    # the hand-worked cases above, as motmetrics sees them
    truth = make_truth([(k, t, x, 0) for k in range(6) for t, x in ((1, 0), (2, 1000))])
    rows = [(k, 10, 0, 10) for k in (0, 1, 3, 4, 5)]
    rows += [(k, 20 if k < 3 else 21, 1000, 20) for k in range(6)] + [(4, 99, 5000, 5000)]
    _compare(clear_mot(make_tracks(rows), truth), _motmetrics(truth, make_tracks(rows), 500.0))
    truth = make_truth([(k, 7, 0, 0) for k in range(3)])
    tracks = make_tracks(
        [
            (0, 1, 50, 0),
            (0, 2, 300, 0),
            (1, 1, 100, 0),
            (1, 2, 10, 0),
            (2, 1, 600, 0),
            (2, 2, 10, 0),
        ]
    )
    _compare(clear_mot(tracks, truth), _motmetrics(truth, tracks, 500.0))
    truth = make_truth([(k, 7, 0, 0) for k in range(3)])
    tracks = make_tracks([(0, 1, 5, 0), (2, 1, 200, 0), (2, 2, 10, 0)])
    _compare(clear_mot(tracks, truth), _motmetrics(truth, tracks, 500.0))
    truth = make_truth([(0, 1, 0, 0), (1, 1, 0, 0), (1, 2, 900, 0), (2, 1, 0, 0), (2, 2, 200, 0)])
    tracks = make_tracks([(0, 5, 0, 0), (1, 5, 900, 0), (2, 5, 150, 0)])
    _compare(clear_mot(tracks, truth, match_distance=300), _motmetrics(truth, tracks, 300.0))


# A frozen scenario: tests/metrics/conftest.py::_random_run(2, n_targets=3, n_scans=12)
# with coordinates rounded to 0.1 m, rows (scan, id, x, y).
TRUTH = [
    (0, 2, 165.4, 824.9), (1, 1, 2177.9, 555.5), (1, 2, 145.6, 836.3),
    (2, 1, 2170.2, 547.3), (2, 2, 125.8, 847.7), (3, 1, 2162.4, 539.0),
    (3, 2, 106.0, 859.0), (4, 1, 2154.6, 530.8), (4, 2, 86.2, 870.4),
    (5, 0, 206.5, 1922.5), (5, 1, 2146.9, 522.6), (5, 2, 66.4, 881.8),
    (6, 0, 192.7, 1946.9), (6, 1, 2139.1, 514.4), (6, 2, 46.6, 893.2),
    (7, 0, 178.8, 1971.4), (7, 1, 2131.3, 506.2), (7, 2, 26.8, 904.5),
    (8, 2, 7.0, 915.9), (9, 2, -12.8, 927.3), (10, 2, -32.6, 938.6),
]  # fmt: skip
TRACKS = [
    (0, 102, 230.9, 752.0), (1, 101, 2200.5, 595.2), (1, 102, 24.3, 930.3),
    (2, 101, 1989.6, 648.2), (2, 102, 255.2, 934.3), (3, 101, 2266.6, 403.5),
    (3, 102, 135.2, 1075.2), (3, 1000, 2117.3, 960.9), (4, 101, 206.2, 1155.4),
    (4, 102, 2173.1, 676.7), (4, 1000, 2071.7, 1011.7), (4, 1001, 585.4, 534.8),
    (5, 100, 2057.8, 580.0), (5, 101, -84.1, 775.6), (5, 102, 215.4, 2103.7),
    (5, 1000, 2056.9, 1043.8), (5, 1001, 585.4, 492.6), (5, 1002, 122.0, 861.3),
    (6, 100, 364.1, 1866.8), (6, 102, 2038.7, 487.7), (6, 1000, 2056.5, 996.7),
    (6, 1001, 563.9, 468.2), (6, 1002, 118.1, 900.5), (7, 102, 2169.6, 451.4),
    (8, 1003, -107.6, 958.4), (8, 1004, 2928.6, 1839.0), (8, 1005, 280.1, 788.7),
    (9, 1003, -78.7, 863.4), (9, 1004, 2927.1, 1864.6), (9, 1006, 2942.7, 107.7),
    (10, 1003, -85.9, 1187.7), (10, 1004, 2945.0, 1815.8), (10, 1006, 2878.8, 138.0),
    (11, 1004, 2940.5, 1797.0), (11, 1006, 2923.0, 105.0),
]  # fmt: skip
# Frozen with motmetrics 1.4.0 (numpy 2.4.6, pandas 3.1.1, scipy solver): one
# MOTAccumulator(auto_id=False).update(target_ids, track_ids, D, frameid=scan) per scan of
# the union, D = Euclidean distances with np.nan where D > 300; then
# mm.metrics.create().compute(acc, metrics=[...], return_dataframe=False).
MM_FROZEN = {
    "mota": -0.23809523809523814, "motp": 135.72909874067298, "num_switches": 6,
    "num_fragmentations": 2, "num_detections": 18, "num_misses": 3,
    "num_false_positives": 17, "num_objects": 21,
}  # fmt: skip


def test_frozen_motmetrics_reference(make_truth, make_tracks):
    truth, tracks = make_truth(TRUTH), make_tracks(TRACKS)
    r = clear_mot(tracks, truth, match_distance=300.0)
    _compare(r, MM_FROZEN)
    # MOTA = 1 − (3 + 17 + 6)/21
    assert r.mota == pytest.approx(1 - 26 / 21)


def test_frozen_scenario_live(make_truth, make_tracks):
    truth, tracks = make_truth(TRUTH), make_tracks(TRACKS)
    _compare(clear_mot(tracks, truth, match_distance=300.0), _motmetrics(truth, tracks, 300.0))
