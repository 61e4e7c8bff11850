"""Asynchronous tracks scored at the truth's times (metrics.resample, evaluate(at=...)):
hand-worked resampling, closed forms, max-age boundary, a naive reference, the synchronous
special case, coverage, and motmetrics on resampled data."""

import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from mhtrack.metrics import evaluate
from mhtrack.metrics.resample import (
    DEFAULT_MAX_AGE_S,
    alignment,
    is_synchronous,
    tracks_at_times,
)
from mhtrack.records import PlotTable, TrackTable, TruthTable


def _tt(rows, tentative=None):
    """TrackTable from ``(scan, time, track_id, x, y, vx, vy, plot)`` rows, in that order."""
    a = np.array(rows, dtype=np.float64).reshape(-1, 8)
    i = a.astype(np.int64)
    return TrackTable(i[:, 0], a[:, 1], i[:, 2], a[:, 3], a[:, 4], a[:, 5], a[:, 6], i[:, 7],
                      tentative=None if tentative is None else np.asarray(tentative, bool))


def _truth_cv(ids, starts, vels, times, scans=None):
    """Constant-velocity truth: target ``ids[i]`` at ``starts[i] + vels[i]·t``."""
    times = np.asarray(times, float)
    scans = np.arange(len(times)) if scans is None else np.asarray(scans)
    rows = []
    for k, t in zip(scans, times, strict=True):
        for i, (sx, sy), (vx, vy) in zip(ids, starts, vels, strict=True):
            rows.append((k, t, i, sx + vx * t, sy + vy * t, vx, vy))
    a = np.array(rows, dtype=np.float64)
    return TruthTable(a[:, 0].astype(np.int64), a[:, 1], a[:, 2].astype(np.int64), a[:, 3],
                      a[:, 4], a[:, 5], a[:, 6])


# ---------------------------------------------------------------- hand-worked resampling

def test_hand_worked_resampling_two_tracks_and_a_stale_one():
    # Track 1: rows at t = 0 (x = 0, vx = 10, plot 5) and t = 4 (x = 40, plot 6).
    # Track 2: one row at t = 1 (x = 100, vx = -5, y = 7, vy = 2).
    # Truth times 0, 2, 4, 5, 7 (scans 10..14), max age 2 s:
    #   t=0: track 1 exact (x 0, plot 5); track 2 has no row yet (t_k = 1 > 0).
    #   t=2: track 1 from t_k=0, age 2 (= max age, kept): x = 0 + 10·2 = 20, plot -1;
    #        track 2 from t_k=1, age 1: x = 100 - 5 = 95, y = 7 + 2 = 9.
    #   t=4: track 1 exact: 40, plot 6; track 2 age 3 > 2: stale, dropped.
    #   t=5: track 1 age 1: 50.   t=7: track 1 age 3: dropped.
    tracks = _tt([(0, 0.0, 1, 0, 0, 10, 0, 5), (2, 4.0, 1, 40, 0, 10, 0, 6),
                  (1, 1.0, 2, 100, 7, -5, 2, 7)], tentative=[True, False, True])
    out = tracks_at_times(tracks, [0, 2, 4, 5, 7], [10, 11, 12, 13, 14], 2.0)
    assert out.scan.tolist() == [10, 11, 11, 12, 13]
    assert out.time.tolist() == [0, 2, 2, 4, 5]
    assert out.track_id.tolist() == [1, 1, 2, 1, 1]
    assert out.x.tolist() == [0, 20, 95, 40, 50]
    assert out.y.tolist() == [0, 0, 9, 0, 0]
    assert out.vx.tolist() == [10, 10, -5, 10, 10]
    assert out.plot.tolist() == [5, -1, -1, 6, -1]
    assert out.tentative.tolist() == [True, True, True, False, False]
    assert out.P is None


def test_max_age_boundary_is_inclusive():
    tracks = _tt([(0, 0.0, 1, 0, 0, 1, 0, -1)])
    times = [0.0, 2.0, 2.5]
    assert tracks_at_times(tracks, times, [0, 1, 2], 2.0).time.tolist() == [0.0, 2.0]
    assert tracks_at_times(tracks, times, [0, 1, 2], 2.5).time.tolist() == [0.0, 2.0, 2.5]
    assert tracks_at_times(tracks, times, [0, 1, 2], 0.0).time.tolist() == [0.0]
    assert tracks_at_times(tracks, times, [0, 1, 2], math.inf).time.tolist() == times
    # a row after the truth time is never used for it ("at or before")
    later = _tt([(0, 0.25, 1, 0, 0, 1, 0, -1)])
    assert len(tracks_at_times(later, [0.0], [0], 10.0)) == 0


def test_bad_arguments():
    tracks = _tt([(0, 0.0, 1, 0, 0, 1, 0, -1)])
    for bad in (-1.0, float("nan"), "x", True):
        with pytest.raises(ValueError, match="max_age_s"):
            tracks_at_times(tracks, [0.0], [0], bad)
    with pytest.raises(ValueError, match="same length"):
        tracks_at_times(tracks, [0.0, 1.0], [0], 1.0)
    with pytest.raises(ValueError, match="finite"):
        tracks_at_times(tracks, [np.nan], [0], 1.0)
    truth = _truth_cv([1], [(0, 0)], [(1, 0)], [0.0, 1.0])
    with pytest.raises(ValueError, match="at must be"):
        evaluate(tracks, truth, at="time")
    with pytest.raises(ValueError, match="scans applies"):
        evaluate(tracks, truth, at="truth-times", scans=[5])
    assert len(tracks_at_times(TrackTable.empty(), [0.0], [0], 1.0)) == 0


def _naive(tracks, times, scans, max_age):
    """Reference resampling: a plain loop over (time, track)."""
    rows = []
    for t, k in zip(times, scans, strict=True):
        for tid in np.unique(tracks.track_id):
            r = np.flatnonzero((tracks.track_id == tid) & (tracks.time <= t))
            if len(r) == 0:
                continue
            j = r[tracks.time[r] == tracks.time[r].max()][-1]  # latest; ties: last row
            dt = t - tracks.time[j]
            if dt <= max_age:
                rows.append((k, int(tid), tracks.x[j] + tracks.vx[j] * dt,
                             tracks.y[j] + tracks.vy[j] * dt))
    rows.sort(key=lambda r: (r[0], r[1]))
    return rows


def test_a_query_max_age_after_a_row_in_floats_is_kept():
    """``0.9 − 0.2 ≤ 0.7`` in floats although ``0.2 + 0.7 < 0.9``: the row at 0.2 is no
    older than 0.7 s at 0.9 and is reported there (found by the naive-loop test)."""
    assert 0.9 - 0.2 <= 0.7 and 0.2 + 0.7 < 0.9
    tracks = TrackTable(np.arange(1), np.array([0.2]), np.array([2]), np.zeros(1),
                        np.zeros(1), np.ones(1), np.zeros(1), np.full(1, -1))
    out = tracks_at_times(tracks, np.array([0.9]), np.array([4]), 0.7)
    assert out.scan.tolist() == [4] and out.track_id.tolist() == [2]


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), max_age=st.sampled_from([0.0, 0.7, 2.0, 5.0]))
@example(seed=1131481, max_age=0.7)  # the boundary case above, among random tracks
def test_agrees_with_a_naive_loop(seed, max_age):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 40))
    t = np.round(rng.uniform(0, 10, n), 1)  # 0.1 s grid: equal times happen
    tracks = TrackTable(np.arange(n), t, rng.integers(0, 5, n), rng.normal(0, 100, n),
                        rng.normal(0, 100, n), rng.normal(0, 10, n), rng.normal(0, 10, n),
                        np.full(n, -1))
    times = np.round(np.sort(rng.uniform(-1, 12, int(rng.integers(0, 15)))), 1)
    times = np.unique(times)
    scans = np.arange(len(times)) + 3
    out = tracks_at_times(tracks, times, scans, max_age)
    ref = _naive(tracks, times, scans, max_age)
    assert list(zip(out.scan.tolist(), out.track_id.tolist(), strict=True)) == \
        [(r[0], r[1]) for r in ref]
    np.testing.assert_allclose(out.x, [r[2] for r in ref], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(out.y, [r[3] for r in ref], rtol=1e-12, atol=1e-9)


# ---------------------------------------------------------------- closed forms

def _shifted_tracks(truth_ids, starts, vels, shift, t_end, dv=(0.0, 0.0)):
    """Each target reported exactly (position) every 1 s at times ``k + shift``, with its
    velocity plus ``dv``."""
    rows = []
    times = np.arange(-1.0, t_end + 1.0) + shift
    for k, t in enumerate(times):
        for i, (sx, sy), (vx, vy) in zip(truth_ids, starts, vels, strict=True):
            rows.append((k, t, i + 100, sx + vx * t, sy + vy * t, vx + dv[0], vy + dv[1], -1))
    return _tt(rows)


def test_track_equal_to_truth_at_shifted_times_scores_zero():
    # Truth sampled at t = 0..10; tracks report the exact state at t = k + 0.3 with the
    # true velocity: predicted by 0.7 s to each truth time, the CV prediction is exact, so
    # OSPA = GOSPA = 0, MOTA = 1 and every truth state is covered.
    ids, starts, vels = [1, 2], [(100.0, 0.0), (-3000.0, 500.0)], [(50.0, -30.0), (0, 120)]
    truth = _truth_cv(ids, starts, vels, np.arange(11.0))
    tracks = _shifted_tracks(ids, starts, vels, 0.3, 10)
    ev = evaluate(tracks, truth)
    assert ev.at == "truth-times" and ev.max_age_s == DEFAULT_MAX_AGE_S
    assert ev.scans.tolist() == list(range(11))
    assert ev.ospa_mean == pytest.approx(0.0, abs=1e-9)
    assert ev.gospa_mean == pytest.approx(0.0, abs=1e-9)
    assert ev.clear_mot.mota == 1.0 and ev.coverage == 1.0
    assert ev.n_track_ids == ev.n_tracks == 2 and ev.n_targets == 2


def test_velocity_error_gives_its_closed_form_ospa():
    # Same, one target, velocity off by (3, 4) m/s: at each truth time the state is 0.7 s
    # old, so the error is |dv|·0.7 = 5·0.7 = 3.5 m; one truth, one track: OSPA = 3.5 m.
    truth = _truth_cv([1], [(0.0, 0.0)], [(200.0, 0.0)], np.arange(6.0))
    tracks = _shifted_tracks([1], [(0.0, 0.0)], [(200.0, 0.0)], 0.3, 5, dv=(3.0, 4.0))
    ev = evaluate(tracks, truth, cutoff=100.0)
    np.testing.assert_allclose(ev.ospa.distance, 3.5, rtol=1e-9)
    assert ev.clear_mot.motp == pytest.approx(3.5, rel=1e-9)
    # ages over 0.7 s are refused: no track at any truth time, OSPA = c
    ev = evaluate(tracks, truth, cutoff=100.0, max_age_s=0.5)
    assert ev.ospa.distance.tolist() == [100.0] * 6 and ev.coverage == 0.0


# ---------------------------------------------------------------- synchronous special case

def _with_plots(truth, tracks, rng):
    """Plots = the truth rows (origin = target); each track row uses a random plot of its
    scan, or none."""
    plots = PlotTable(truth.scan, truth.time, np.zeros(len(truth), np.int64), truth.x,
                      truth.y, origin=truth.target_id)
    plot = np.full(len(tracks), -1)
    for r in range(len(tracks)):
        rows = np.flatnonzero(truth.scan == tracks.scan[r])
        if len(rows) and rng.random() < 0.8:
            plot[r] = rng.choice(rows)
    return plots, plot


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])  # a pure builder
@given(seed=st.integers(0, 2**32 - 1))
def test_tracks_at_the_truth_times_score_as_the_synchronous_path(seed, random_run):
    truth, tracks = random_run(seed % 1000)
    tracks = tracks.take(np.isin(tracks.scan, truth.scan))  # no track row without truth
    rng = np.random.default_rng(seed)
    plots, plot = _with_plots(truth, tracks, rng)
    tent = rng.random(len(tracks)) < 0.2
    tracks = TrackTable(tracks.scan, tracks.time, tracks.track_id, tracks.x, tracks.y,
                        rng.normal(0, 9, len(tracks)), rng.normal(0, 9, len(tracks)), plot,
                        tentative=tent)
    # Resampled with a max age below the 1 s scan period, each truth time takes exactly
    # the rows at that time (a track absent at a scan stays absent): same numbers.
    sync = evaluate(tracks, truth, plots=plots)
    asyn = evaluate(tracks, truth, plots=plots, at="truth-times", max_age_s=0.5)
    assert sync.at == "scans" and asyn.at == "truth-times"
    a, b = sync.to_dict(), asyn.to_dict()
    assert a.pop("at") == "scans" and "max_age_s" not in a
    assert b.pop("at") == "truth-times" and b.pop("max_age_s") == 0.5
    assert json.dumps(a) == json.dumps(b)  # bit-identical, NaN/None included
    # with the default 15 s a track's last state also fills the scans after it: more rows
    longer = evaluate(tracks, truth, plots=plots, at="truth-times")
    assert longer.max_age_s == DEFAULT_MAX_AGE_S
    assert np.all(longer.cardinality.n_tracks >= sync.cardinality.n_tracks)


def test_alignment_is_chosen_from_the_times(make_truth, make_tracks):
    truth = make_truth([(0, 1, 0, 0), (1, 1, 0, 0)])
    tracks = make_tracks([(0, 5, 0, 0), (1, 5, 0, 0), (7, 6, 0, 0)])  # scan 7: no truth
    assert is_synchronous(tracks, truth) and alignment(tracks, truth) == "scans"
    late = TrackTable(tracks.scan, tracks.time + 0.4, *(getattr(tracks, f) for f in
                      ("track_id", "x", "y", "vx", "vy", "plot")))
    assert alignment(late, truth) == "truth-times"
    assert alignment(late, truth, at="scans") == "scans"
    timed = PlotTable(np.array([0]), np.array([0.0]), np.array([0]), np.array([0.0]),
                      np.array([0.0]), timed=True)
    assert alignment(tracks, truth, timed) == "truth-times"
    ev = evaluate(late, truth, plots=timed)
    assert ev.at == "truth-times" and math.isnan(ev.association.rcc)
    assert ev.to_dict()["rcc"] is None


# ---------------------------------------------------------------- coverage

def test_coverage_hand_worked(make_truth, make_tracks):
    # Targets 1 (x = 0) and 2 (x = 1000) alive at scans 0–3: 8 truth states. Track 10 on
    # target 1 at every scan, track 20 on target 2 at scans 2–3 only, track 30 far away
    # (false). Matched states: 4 + 2 = 6, coverage 6/8; 3 track ids, 2 targets.
    truth = make_truth([(k, t, x, 0) for k in range(4) for t, x in ((1, 0), (2, 1000))])
    rows = [(k, 10, 0, 10) for k in range(4)] + [(k, 20, 1000, -20) for k in (2, 3)]
    rows += [(k, 30, 9000, 9000) for k in range(4)]
    ev = evaluate(make_tracks(rows), truth)
    assert ev.coverage == 6 / 8
    d = ev.to_dict()
    assert (d["coverage"], d["n_track_ids"], d["n_targets"]) == (0.75, 3, 2)
    assert "coverage (matched truth states)" in ev.to_table()
    # no truth: coverage undefined
    assert evaluate(make_tracks(rows), make_truth([])).to_dict()["coverage"] is None


def test_coverage_of_asynchronous_tracks_hand_worked():
    # Truth: one target at rest at (0, 0), sampled at t = 0, 5, 10, 15, 20 (scans 0–4).
    # Track 7 reports it at t = 1 and t = 12 only (max age 6 s): t = 5 uses t_k = 1 (age 4),
    # t = 10 is 9 s after t = 1 (stale), t = 15 uses 12 (age 3), t = 20 is 8 s old (stale);
    # t = 0 precedes the first row. Covered: 5 and 15 -> 2 of 5 states, coverage 0.4.
    truth = _truth_cv([1], [(0.0, 0.0)], [(0.0, 0.0)], [0.0, 5, 10, 15, 20])
    tracks = _tt([(0, 1.0, 7, 3, 4, 0, 0, -1), (1, 12.0, 7, 0, 0, 0, 0, -1)])
    ev = evaluate(tracks, truth, max_age_s=6.0)
    assert ev.at == "truth-times" and ev.coverage == 0.4
    assert ev.clear_mot.motp == pytest.approx(2.5)  # distances 5 and 0
    assert ev.cardinality.n_tracks.tolist() == [0, 1, 0, 1, 0]


# ---------------------------------------------------------------- motmetrics on async data

@pytest.mark.parametrize("seed", range(4))
def test_async_clear_mot_against_motmetrics_live(seed):
    mm = pytest.importorskip("motmetrics")
    rng = np.random.default_rng(seed)
    ids = np.arange(5)
    starts = rng.uniform(0, 3000, (5, 2))
    vels = rng.normal(0, 40, (5, 2))
    truth = _truth_cv(ids, starts, vels, np.arange(0.0, 40.0, 2.0))
    rows = []  # per target: reports every 0.9 s from a random start, noisy, with dropouts
    for i in ids:
        tid = 100 + i
        for k, t in enumerate(np.arange(rng.uniform(0, 10), 40.0, 0.9)):
            if rng.random() < 0.1:
                continue
            if rng.random() < 0.03:
                tid += 1000
            p = starts[i] + vels[i] * t + rng.normal(0, 60, 2)
            rows.append((k, t, tid, *p, *vels[i], -1))
    tracks = _tt(rows)
    ev = evaluate(tracks, truth, match_distance=250.0, max_age_s=3.0)
    assert ev.at == "truth-times"
    acc = mm.MOTAccumulator(auto_id=False)
    ref = _naive(tracks, np.arange(0.0, 40.0, 2.0), np.arange(20), 3.0)
    for s in range(20):
        o = truth.target_id[truth.scan == s]
        a = truth.positions[truth.scan == s]
        h = [r[1] for r in ref if r[0] == s]
        b = np.array([r[2:] for r in ref if r[0] == s]).reshape(-1, 2)
        dist = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=-1)
        dist[dist > 250.0] = np.nan
        acc.update(o, h, dist, frameid=s)
    m = mm.metrics.create().compute(
        acc, metrics=["mota", "num_switches", "num_detections", "num_objects"],
        return_dataframe=False)
    assert ev.clear_mot.mota == pytest.approx(m["mota"], rel=1e-12)
    assert ev.clear_mot.id_switches == m["num_switches"]
    assert ev.coverage == pytest.approx(m["num_detections"] / m["num_objects"], rel=1e-12)
