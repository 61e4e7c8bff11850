"""evaluate(): the combined report against hand formulas and its output formats."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from mhtrack.metrics import Evaluation, evaluate
from mhtrack.records import PlotTable, TrackTable, TruthTable


def _as_tracks(truth: TruthTable, keep: np.ndarray | None = None) -> TrackTable:
    """Tracks reporting the truth exactly (track id = target id), optionally some rows only."""
    keep = np.ones(len(truth), bool) if keep is None else keep
    return TrackTable(
        truth.scan[keep],
        truth.time[keep],
        truth.target_id[keep],
        truth.x[keep],
        truth.y[keep],
        truth.vx[keep],
        truth.vy[keep],
        np.full(keep.sum(), -1, np.int64),
    )


REQUIRED_KEYS = {
    "ospa_mean", "gospa_mean", "cardinality_error_mean", "mota", "motp", "id_switches",
    "fragmentations", "n_tracks", "ospa", "gospa", "cardinality", "cardinality_true", "scans",
    "rcc", "rmc", "rfg", "l_min", "l_avg", "l_max",
}  # fmt: skip


def test_identical_tracks_and_truth(random_run):
    truth, _ = random_run(3)
    ev = evaluate(_as_tracks(truth), truth)
    assert ev.ospa_mean == 0 and ev.gospa_mean == 0 and ev.cardinality_error_mean == 0
    assert ev.clear_mot.mota == 1.0 and ev.clear_mot.motp == 0.0
    assert ev.clear_mot.id_switches == 0 and ev.clear_mot.fragmentations == 0
    assert ev.n_tracks == ev.n_targets == len(np.unique(truth.target_id))


@pytest.mark.parametrize(("c", "p"), [(500.0, 2.0), (300.0, 1.0), (1000.0, 3.0)])
def test_one_target_removed(random_run, c, p):
    # Tracks = truth exactly, minus one target. At a scan with m truths where that target
    # is alive, the other m − 1 are matched at distance 0:
    #   OSPA = (c^p · 1/m)^(1/p),  GOSPA = (c^p/2)^(1/p),  cardinality error 1;
    # elsewhere all three are 0.
    truth, _ = random_run(5)
    ids, counts = np.unique(truth.target_id, return_counts=True)
    gone = int(ids[np.argmin(counts)])  # a short-lived target: scans with and without it
    ev = evaluate(_as_tracks(truth, truth.target_id != gone), truth, cutoff=c, order=p)
    m = np.array([np.sum(truth.scan == s) for s in ev.scans])
    alive = np.array([np.any((truth.scan == s) & (truth.target_id == gone)) for s in ev.scans])
    assert alive.any() and (~alive).any()
    expected = np.where(alive, (c**p / m) ** (1 / p), 0.0)
    np.testing.assert_allclose(ev.ospa.distance, expected, rtol=1e-12)
    np.testing.assert_allclose(ev.gospa.distance, np.where(alive, c / 2 ** (1 / p), 0), rtol=1e-12)
    assert ev.cardinality.error.tolist() == alive.astype(int).tolist()
    assert ev.ospa_mean == pytest.approx(expected.mean())
    # CLEAR-MOT: only misses, MOTA = 1 − (#rows of the removed target)/GT
    n_gone = int(np.sum(truth.target_id == gone))
    assert ev.clear_mot.mota == pytest.approx(1 - n_gone / len(truth))
    assert ev.clear_mot.n_misses == n_gone and ev.clear_mot.n_false == 0


def test_match_distance_defaults_to_cutoff(make_truth, make_tracks):
    truth = make_truth([(0, 1, 0, 0), (1, 1, 0, 0)])
    tracks = make_tracks([(0, 9, 100, 0), (1, 9, 100, 0)])  # 100 m off
    assert evaluate(tracks, truth, cutoff=50).clear_mot.n_matches == 0
    assert evaluate(tracks, truth, cutoff=150).clear_mot.n_matches == 2
    ev = evaluate(tracks, truth, cutoff=50, match_distance=150)
    assert ev.clear_mot.n_matches == 2 and ev.match_distance == 150


def test_plots_and_explicit_scans_extend_the_scans(make_truth, make_tracks):
    truth = make_truth([(2, 1, 0, 0), (3, 1, 0, 0)])
    tracks = make_tracks([(2, 4, 0, 0), (3, 4, 0, 0)])
    e = np.zeros(0)
    plots = PlotTable(
        np.zeros(0, np.int64),
        e,
        np.zeros(0, np.int64),
        e,
        e,
        scan_times=(np.arange(0, 6), np.arange(0, 6) * 1.0),
    )
    ev = evaluate(tracks, truth, plots=plots, scans=[8])
    assert ev.scans.tolist() == [0, 1, 2, 3, 4, 5, 8]
    assert ev.ospa.distance.tolist() == [0.0] * 7
    assert ev.cardinality.n_tracks.tolist() == [0, 0, 1, 1, 0, 0, 0]
    # a track gap on scan 3 now: OSPA c there, averaged over all 7 scans
    ev = evaluate(make_tracks([(2, 4, 0, 0)]), truth, plots=plots, scans=[8], cutoff=70)
    assert ev.ospa_mean == pytest.approx(70 / 7)


def test_to_dict_is_json_and_consistent(random_run):
    truth, tracks = random_run(1)
    ev = evaluate(tracks, truth)
    d = ev.to_dict()
    assert d.keys() >= REQUIRED_KEYS
    json.loads(json.dumps(d, allow_nan=False))  # strict JSON: no NaN/inf, plain types
    n = len(d["scans"])
    assert n == len(d["ospa"]) == len(d["gospa"]) == len(d["cardinality"])
    assert n == len(d["cardinality_true"])
    assert d["ospa_mean"] == pytest.approx(np.mean(d["ospa"]))
    err = np.abs(np.array(d["cardinality"]) - d["cardinality_true"])
    assert d["cardinality_error_mean"] == pytest.approx(err.mean())
    assert d["n_tracks"] == len(np.unique(tracks.track_id))
    # no plots: no association rates; breaks and track life come from the matching alone
    assert d["rcc"] is None and d["rmc"] is None
    assert d["rfg"] is not None and 0 <= d["l_min"] <= d["l_avg"] <= d["l_max"]


def test_to_dict_of_a_hand_worked_run(make_truth, make_tracks):
    """Two targets over scans 0–3 (time = scan), c = d_match = 100 m, p = 2.

    Target 1 at (0, 0): track 10 at (30, 40), 50 m off, at scans 0, 1, 3 (missed at 2).
    Target 2 at (1000, 0): track 20 exactly at scans 0, 1, then track 21 at 2, 3 (one
    identity switch). A false track 99 far away at scan 3.
    """
    truth = make_truth([(k, t, x, 0) for k in range(4) for t, x in ((1, 0), (2, 1000))])
    tracks = make_tracks([(k, 10, 30, 40) for k in (0, 1, 3)]
                         + [(k, 20 if k < 2 else 21, 1000, 0) for k in range(4)]
                         + [(3, 99, 5000, 5000)])
    d = evaluate(tracks, truth, cutoff=100.0).to_dict()
    # CLEAR-MOT: GT 8, 7 matches, 1 miss, 1 false, 1 switch -> MOTA 1 - 3/8;
    # MOTP (3·50 + 4·0)/7; target 1 tracked, lost, tracked again: 1 fragmentation
    assert (d["n_truth"], d["n_matches"], d["n_misses"], d["n_false"]) == (8, 7, 1, 1)
    assert d["id_switches"] == 1 and d["fragmentations"] == 1
    assert d["mota"] == pytest.approx(1 - 3 / 8) and d["motp"] == pytest.approx(150 / 7)
    # OSPA per scan: sqrt((50² + 0)/2), same, sqrt(100²/2) (one missing), and at scan 3
    # three tracks for two truths: sqrt((50² + 0 + 100²)/3)
    ospa = [np.sqrt(1250), np.sqrt(1250), np.sqrt(5000), np.sqrt(12500 / 3)]
    np.testing.assert_allclose(d["ospa"], ospa, rtol=1e-12)
    assert d["ospa_mean"] == pytest.approx(np.mean(ospa))
    # GOSPA (α = 2): a miss or a false track costs c²/2
    np.testing.assert_allclose(d["gospa"], np.sqrt([2500, 2500, 5000, 7500]), rtol=1e-12)
    assert d["cardinality"] == [2, 2, 1, 3] and d["cardinality_true"] == [2, 2, 2, 2]
    assert d["cardinality_error_mean"] == 0.5
    assert (d["n_tracks"], d["n_targets"], d["n_scans"]) == (4, 2, 4)
    # P1 Table 3: one break per target (lost; switched) -> Rfg 1; the longest run of each
    # is two scans, 1 s + T (T = 1 s); no plots, no Rcc/Rmc; both found at their first scan
    assert d["rfg"] == 1.0 and d["l_min"] == d["l_avg"] == d["l_max"] == 2.0
    assert d["rcc"] is None and d["rmc"] is None
    assert d["delay"] == [0.0, 0.0] and d["delay_max"] == 0.0


def test_tables_are_checked_once(random_run, monkeypatch):
    """evaluate checks and indexes the tables once for all its metrics."""
    import importlib

    modules = [importlib.import_module(f"mhtrack.metrics.{m}") for m in
               ("_common", "association", "cardinality", "clearmot", "gospa", "ospa",
                "evaluate")]
    common = modules[0]
    calls = []
    checked = common.check_tables

    def counting(tracks, truth):
        calls.append(1)
        return checked(tracks, truth)

    for module in modules:
        if hasattr(module, "check_tables"):
            monkeypatch.setattr(module, "check_tables", counting)
    truth, tracks = random_run(2)
    evaluate(replace(tracks, tentative=np.arange(len(tracks)) % 3 == 0), truth)
    assert len(calls) == 1


def test_to_dict_without_truth_has_nulls():
    empty_truth = TruthTable(*([np.zeros(0)] * 7))
    d = evaluate(TrackTable.empty(), empty_truth).to_dict()
    assert d["mota"] is None and d["motp"] is None and d["ospa_mean"] is None
    assert d["scans"] == [] and d["n_tracks"] == 0
    assert all(d[k] is None for k in ("rcc", "rmc", "rfg", "l_min", "l_avg", "l_max"))
    json.dumps(d, allow_nan=False)


def test_to_table(make_truth, make_tracks):
    truth = make_truth([(0, 1, 0, 0), (1, 1, 0, 0)])
    tracks = make_tracks([(0, 9, 30, 40), (1, 9, 30, 40)])  # 50 m off each scan
    ev = evaluate(tracks, truth, cutoff=100)
    text = ev.to_table()
    assert isinstance(ev, Evaluation)
    lines = text.splitlines()
    assert lines[0].split() == ["metric", "value"]
    assert any(
        line.startswith("OSPA mean (c=100 m, p=2)") and line.endswith("50 m") for line in lines
    )
    assert any(line.startswith("MOTA") and line.endswith(" 1") for line in lines)
    assert text.isascii()
    per_scan = ev.to_table(per_scan=True).split("\n\n")[1].splitlines()
    assert per_scan[0].split() == ["scan", "n_true", "n_tracks", "OSPA", "GOSPA"]
    assert [r.split()[:3] for r in per_scan[2:]] == [["0", "1", "1"], ["1", "1", "1"]]


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"cutoff": -1.0}, "cutoff"),
        ({"cutoff": float("nan")}, "cutoff"),
        ({"order": 0.5}, "order"),
        ({"order": float("inf")}, "order"),
        ({"match_distance": -3.0}, "match_distance"),
        ({"match_distance": float("nan")}, "match_distance"),
        ({"scans": [1.5]}, "scans"),
        ({"scans": [[1, 2]]}, "scans"),
    ],
)
def test_invalid_arguments(kw, match, make_truth, make_tracks):
    truth, tracks = make_truth([(0, 1, 0, 0)]), make_tracks([(0, 1, 0, 0)])
    with pytest.raises(ValueError, match=match):
        evaluate(tracks, truth, **kw)


def test_invalid_tables(make_truth, make_tracks):
    truth, tracks = make_truth([(0, 1, 0, 0)]), make_tracks([(0, 1, 0, 0)])
    with pytest.raises(TypeError, match="tracks must be a TrackTable"):
        evaluate(truth, tracks)
    with pytest.raises(TypeError, match="plots must be a PlotTable"):
        evaluate(tracks, truth, plots=[0, 1])
    with pytest.raises(ValueError, match="non-finite"):
        evaluate(replace(tracks, x=np.array([np.nan])), truth)
    dup = make_truth([(0, 1, 0, 0), (0, 1, 5, 5)])
    with pytest.raises(ValueError, match="truth has a repeated"):
        evaluate(tracks, dup)


def test_row_order_of_inputs_does_not_matter(random_run):
    truth, tracks = random_run(4)
    perm = np.random.default_rng(0).permutation(len(tracks))
    shuffled = TrackTable(
        *(
            getattr(tracks, f)[perm]
            for f in ("scan", "time", "track_id", "x", "y", "vx", "vy", "plot")
        )
    )
    a, b = evaluate(tracks, truth).to_dict(), evaluate(shuffled, truth).to_dict()
    assert a == b
    assert math.isfinite(a["mota"])
