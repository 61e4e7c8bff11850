"""P1 Table 3 metrics (Rcc, Rmc, Rfg, track life): hand-worked cases, edges, properties."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.metrics import association_metrics, clear_mot, evaluate
from mhtrack.records import PlotTable, TrackTable, TruthTable

KEYS = ("rcc", "rmc", "rfg", "l_min", "l_avg", "l_max")


def _plots(rows: list[tuple[int, float, float, int]], dt: float = 1.0) -> PlotTable:
    """Plot table from ``(scan, x, y, origin)`` rows, in the given order (time = dt·scan)."""
    a = np.array(rows, dtype=np.float64).reshape(-1, 4)
    scan = a[:, 0].astype(np.int64)
    return PlotTable(
        scan=scan,
        time=scan * dt,
        sensor=np.zeros(len(a), np.int64),
        x=a[:, 1],
        y=a[:, 2],
        origin=a[:, 3].astype(np.int64),
    )


def _truth(rows: list[tuple[int, int, float, float]], dt: float = 1.0) -> TruthTable:
    """Truth from ``(scan, target_id, x, y)`` rows (time = dt·scan, velocities zero)."""
    a = np.array(rows, dtype=np.float64).reshape(-1, 4)
    scan = a[:, 0].astype(np.int64)
    z = np.zeros(len(a))
    return TruthTable(scan, scan * dt, a[:, 1].astype(np.int64), a[:, 2], a[:, 3], z, z)


def _tracks(rows: list[tuple[int, int, float, float, int]], dt: float = 1.0) -> TrackTable:
    """Tracks from ``(scan, track_id, x, y, plot)`` rows (time = dt·scan)."""
    if not rows:
        return TrackTable.empty()
    a = np.array(rows, dtype=np.float64).reshape(-1, 5)
    scan = a[:, 0].astype(np.int64)
    z = np.zeros(len(a))
    return TrackTable(
        scan, scan * dt, a[:, 1].astype(np.int64), a[:, 2], a[:, 3], z, z, a[:, 4].astype(np.int64)
    )


# Hand-worked example: 2 targets, 6 scans (0–5), T = 1 s, matching distance 500 m.
# Target A (id 1) sits at (0, 0), alive 0–5; target B (id 2) at (1000, 0), alive 1–5.
# Far clutter is at (5000, 5000); track 30 follows it (never matched: no effect).
#
#  scan | plots (row: what)            | A: track uses plot -> outcome  | B: track uses plot -> ...
#  0    | 0: A, 1: clutter             | none       -> D, unmatched     | (not alive)
#  1    | 2: A, 3: B                   | 10 uses 2  -> correct          | 20 uses 3  -> correct
#  2    | 4: A, 5: B, 6: clutter@50 m, | 10 uses 6  -> wrong (clutter)  | 20 coasts  -> D, neither
#       | 7: clutter (track 30 uses)   |                                |
#  3    | 8: B, 9: clutter (track 30)  | 10 coasts; A missed: not in D  | 20 uses 8  -> correct
#  4    | 10: A, 11: B                 | 11 uses 10 -> correct          | 20 uses 10 -> wrong (A's)
#  5    | 12: A, 13: B                 | 11 uses 12 -> correct          | none       -> D, unmatched
#
#  D (target detected): A at 0, 1, 2, 4, 5 (5) + B at 1, 2, 3, 4, 5 (5) = 10 pairs.
#  correct: A1, A4, A5, B1, B3 = 5  -> Rcc = 5/10 = 0.5
#  wrong:   A2 (clutter), B4 (A's plot) = 2  -> Rmc = 2/10 = 0.2
#  breaks:  A: 0→1 unmatched→10 (initiation, not a break), 3→4 10→11 (break) = 1
#           B: 4→5 20→none (break) = 1                          -> Rfg = 2 / 2 targets = 1.0
#  runs:    A: 10 on 1–3 = 3−1+1 = 3 s, 11 on 4–5 = 2 s -> life 3 s
#           B: 20 on 1–4 = 4−1+1 = 4 s                   -> life 4 s
#  Lmin = 3, Lavg = 3.5, Lmax = 4.
FAR = (5000.0, 5000.0)
HAND_PLOTS = [
    (0, 0, 0, 1), (0, *FAR, -1),
    (1, 0, 0, 1), (1, 1000, 0, 2),
    (2, 0, 0, 1), (2, 1000, 0, 2), (2, 50, 0, -1), (2, *FAR, -1),
    (3, 1000, 0, 2), (3, *FAR, -1),
    (4, 0, 0, 1), (4, 1000, 0, 2),
    (5, 0, 0, 1), (5, 1000, 0, 2),
]  # fmt: skip
HAND_TRUTH = [(k, 1, 0, 0) for k in range(6)] + [(k, 2, 1000, 0) for k in range(1, 6)]
HAND_TRACKS = [
    (1, 10, 0, 0, 2), (1, 20, 1000, 0, 3),
    (2, 10, 0, 0, 6), (2, 20, 1000, 0, -1), (2, 30, *FAR, 7),
    (3, 10, 0, 0, -1), (3, 20, 1000, 0, 8), (3, 30, *FAR, 9),
    (4, 11, 0, 0, 10), (4, 20, 1000, 0, 10),
    (5, 11, 0, 0, 12),
]  # fmt: skip


def _hand(dt: float = 1.0) -> tuple[TrackTable, TruthTable, PlotTable]:
    return _tracks(HAND_TRACKS, dt), _truth(HAND_TRUTH, dt), _plots(HAND_PLOTS, dt)


def test_hand_worked_example():
    tracks, truth, plots = _hand()
    a = association_metrics(tracks, truth, plots)
    assert (a.n_detected, a.n_correct, a.n_wrong) == (10, 5, 2)
    assert a.rcc == 0.5 and a.rmc == 0.2
    assert a.target_id.tolist() == [1, 2] and a.breaks.tolist() == [1, 1]
    assert a.n_breaks == 2 and a.rfg == 1.0
    assert a.scan_period == 1.0 and a.life.tolist() == [3.0, 4.0]
    assert (a.l_min, a.l_avg, a.l_max) == (3.0, 3.5, 4.0)
    assert a.has_origin


def test_hand_worked_example_through_evaluate():
    tracks, truth, plots = _hand()
    d = evaluate(tracks, truth, plots=plots, cutoff=500).to_dict()
    assert {k: d[k] for k in KEYS} == {
        "rcc": 0.5, "rmc": 0.2, "rfg": 1.0, "l_min": 3.0, "l_avg": 3.5, "l_max": 4.0,
    }  # fmt: skip
    json.dumps(d, allow_nan=False)


def test_track_life_uses_the_time_column():
    # Same run with a 2 s scan period: every duration doubles, the rates do not change.
    a = association_metrics(*_hand(dt=2.0))
    assert a.scan_period == 2.0 and a.life.tolist() == [6.0, 8.0]
    assert (a.rcc, a.rmc, a.rfg) == (0.5, 0.2, 1.0)
    assert association_metrics(*_hand(), scan_period=5.0).life.tolist() == [3 - 1 + 5, 4 - 1 + 5]


def test_without_origin_rates_are_nan_and_continuity_still_computed():
    tracks, truth, plots = _hand()
    for p in (None, replace(plots, origin=None)):
        a = association_metrics(tracks, truth, p)
        assert math.isnan(a.rcc) and math.isnan(a.rmc) and not a.has_origin
        assert a.rfg == 1.0 and a.life.tolist() == [3.0, 4.0]
        d = evaluate(tracks, truth, plots=p).to_dict()
        assert d["rcc"] is None and d["rmc"] is None and d["rfg"] == 1.0 and d["l_max"] == 4.0


def test_no_tracks():
    # Every detected pair is unmatched: Rcc = Rmc = 0; nothing to break: Rfg = 0; L = 0.
    _, truth, plots = _hand()
    a = association_metrics(TrackTable.empty(), truth, plots)
    assert (a.rcc, a.rmc, a.rfg, a.l_min, a.l_avg, a.l_max) == (0, 0, 0, 0, 0, 0)
    assert a.n_detected == 10


def test_no_truth_gives_nan_and_nulls():
    empty_truth = TruthTable(*([np.zeros(0)] * 7))
    a = association_metrics(TrackTable.empty(), empty_truth, None)
    assert all(math.isnan(getattr(a, k)) for k in KEYS) and a.n_targets == 0
    d = evaluate(TrackTable.empty(), empty_truth).to_dict()
    assert all(d[k] is None for k in KEYS)


def test_target_never_matched_has_zero_life():
    # Target 2 is never followed (its only track is 2 km away): life 0, no break;
    # target 1 is followed on scans 0–3 by track 5: life 4 s.
    truth = _truth([(k, 1, 0, 0) for k in range(4)] + [(k, 2, 0, 3000) for k in range(4)])
    tracks = _tracks([(k, 5, 0, 0, -1) for k in range(4)] + [(k, 6, 0, 5000, -1) for k in range(4)])
    a = association_metrics(tracks, truth)
    assert a.life.tolist() == [4.0, 0.0] and a.breaks.tolist() == [0, 0]
    assert (a.l_min, a.l_avg, a.l_max, a.rfg) == (0.0, 2.0, 4.0, 0.0)


def test_initiation_delay_loss_and_truth_gap():
    # One target alive on scans 0–9 except 6 (gap in the truth). Track 7 starts at scan 3
    # (initiation delay 0–2: not a break), misses the target on scan 5 (break 1), follows it
    # again on 7–9 (the gap 6 is not a scan of its life: 7 continues nothing, run 7–9).
    # Runs: 3–4 (2 s), 7–9 (3 s) -> life 3 s; breaks 1.
    scans = [k for k in range(10) if k != 6]
    truth = _truth([(k, 1, 0, 0) for k in scans])
    tracks = _tracks([(k, 7, 0, 0 if k != 5 else 2000, -1) for k in scans if k >= 3])
    a = association_metrics(tracks, truth)
    assert a.breaks.tolist() == [1] and a.life.tolist() == [3.0]
    # the same without the miss: one run 3–9 across the gap, 9 − 3 + 1 = 7 s, no break
    tracks = _tracks([(k, 7, 0, 0, -1) for k in scans if k >= 3])
    a = association_metrics(tracks, truth)
    assert a.breaks.tolist() == [0] and a.life.tolist() == [7.0]


def test_bad_plot_column():
    tracks, truth, plots = _hand()
    with pytest.raises(ValueError, match="not a row of the plots table"):
        association_metrics(replace(tracks, plot=np.full(len(tracks), 99)), truth, plots)
    wrong_scan = tracks.plot.copy()
    wrong_scan[0] = 0  # a plot of scan 0 used at scan 1
    with pytest.raises(ValueError, match="plot of scan 0"):
        association_metrics(replace(tracks, plot=wrong_scan), truth, plots)
    with pytest.raises(TypeError, match="plots must be a PlotTable"):
        association_metrics(tracks, truth, [1, 2])


def test_matches_evaluate_and_clear_mot_matching():
    tracks, truth, plots = _random_with_plots(3, 0.3)
    ev = evaluate(tracks, truth, plots=plots, cutoff=400)
    a = association_metrics(tracks, truth, plots, match_distance=400)
    b = association_metrics(
        tracks, truth, plots, matching=clear_mot(tracks, truth, match_distance=400).matching
    )
    for r in (a, b):
        assert ev.association is not None
        assert [getattr(r, k) for k in KEYS] == [getattr(ev.association, k) for k in KEYS]


def _random_with_plots(
    seed: int, p_wrong: float, n_targets: int = 5, n_scans: int = 30
) -> tuple[TrackTable, TruthTable, PlotTable]:
    """Random truth, plots (P_D 0.8 plus clutter) and noisy tracks that use their target's
    plot, another plot of the scan (probability ``p_wrong``) or none; tracks drop out,
    change id and are confirmed late."""
    rng = np.random.default_rng(seed)
    birth = rng.integers(0, n_scans // 2, n_targets)
    death = rng.integers(n_scans // 2, n_scans + 1, n_targets)
    start = rng.uniform(0, 3000, (n_targets, 2))
    vel = rng.normal(0, 30, (n_targets, 2))
    plot_rows, truth_rows, track_rows = [], [], []
    track_of = np.arange(n_targets) + 100
    next_id = 1000
    for k in range(n_scans):
        pos = start + vel * k
        alive = np.flatnonzero((birth <= k) & (k < death))
        rows_k, base = {}, len(plot_rows)
        for t in alive:
            truth_rows.append((k, int(t), *pos[t]))
            if rng.random() < 0.8:
                rows_k[t] = len(plot_rows)
                plot_rows.append((k, *(pos[t] + rng.normal(0, 50, 2)), int(t)))
        for _ in range(rng.poisson(3)):
            plot_rows.append((k, *rng.uniform(0, 3000, 2), -1))
        for t in alive:
            if k - birth[t] < 2 or rng.random() < 0.1:
                continue  # not confirmed yet, or dropped out
            if rng.random() < 0.05:
                track_of[t], next_id = next_id, next_id + 1
            u = rng.random()
            own = rows_k.get(t, -1)
            n_k = len(plot_rows) - base
            plot = base + int(rng.integers(n_k)) if (u < p_wrong and n_k) else own
            track_rows.append((k, int(track_of[t]), *(pos[t] + rng.normal(0, 80, 2)), plot))
    return _tracks(track_rows), _truth(truth_rows), _plots(plot_rows)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), p_wrong=st.floats(0.0, 1.0))
def test_rates_are_shares_of_one_denominator(seed, p_wrong):
    tracks, truth, plots = _random_with_plots(seed, p_wrong)
    a = association_metrics(tracks, truth, plots)
    assert a.n_correct + a.n_wrong <= a.n_detected
    if a.n_detected:
        assert 0 <= a.rcc <= 1 and 0 <= a.rmc <= 1 and a.rcc + a.rmc <= 1 + 1e-12
    assert np.all(a.life >= 0) and a.l_min <= a.l_avg <= a.l_max
    # a target's longest run cannot outlast its life span
    for tid, life in zip(a.target_id.tolist(), a.life.tolist(), strict=True):
        t = truth.time[truth.target_id == tid]
        assert life <= t.max() - t.min() + a.scan_period + 1e-9
    assert a.rfg >= 0


def test_row_order_does_not_matter():
    tracks, truth, plots = _random_with_plots(11, 0.3)
    rng = np.random.default_rng(1)
    # shuffle plots within each scan (the table stays sorted by scan) and renumber tracks.plot
    perm = np.lexsort((rng.random(len(plots)), plots.scan))
    new_row = np.empty(len(perm), np.int64)
    new_row[perm] = np.arange(len(perm))
    plots2 = PlotTable(
        plots.scan[perm], plots.time[perm], plots.sensor[perm], plots.x[perm], plots.y[perm],
        origin=plots.origin[perm],
    )  # fmt: skip
    plot2 = np.where(tracks.plot >= 0, new_row[np.maximum(tracks.plot, 0)], -1)
    pt, pg = rng.permutation(len(tracks)), rng.permutation(len(truth))
    tracks2 = TrackTable(
        *(getattr(tracks, f)[pt] for f in ("scan", "time", "track_id", "x", "y", "vx", "vy")),
        plot2[pt],
    )
    truth2 = TruthTable(
        *(getattr(truth, f)[pg] for f in ("scan", "time", "target_id", "x", "y", "vx", "vy"))
    )
    a = evaluate(tracks, truth, plots=plots).to_dict()
    b = evaluate(tracks2, truth2, plots=plots2).to_dict()
    assert {k: a[k] for k in KEYS} == {k: b[k] for k in KEYS}
    assert all(a[k] is not None for k in KEYS) and 0 < a["rcc"] < 1 and a["rmc"] > 0


def test_keys_in_to_dict_and_table():
    tracks, truth, plots = _hand()
    ev = evaluate(tracks, truth, plots=plots)
    assert set(KEYS) <= ev.to_dict().keys()
    text = ev.to_table()
    assert "Rcc correct association rate" in text and "3 / 3.5 / 4 s" in text


def test_confirmation_delay_counts_live_scans_before_the_first_online_match():
    """Target 1 alive at scans 1–6, target 2 at 3–6. Track 10 follows target 1 from scan 2,
    its rows at 2–3 backfilled (tentative); track 20 follows target 2 from scan 3 online.
    Target 1's first match reported at its scan is at scan 4: 3 live scans (1, 2, 3) before
    it; target 2's is at its first scan: 0."""
    truth = _truth([(k, 1, 0.0, 0.0) for k in range(1, 7)]
                   + [(k, 2, 1000.0, 0.0) for k in range(3, 7)])
    rows = [(k, 10, 10.0, 0.0, -1) for k in range(2, 7)] + [
        (k, 20, 1010.0, 0.0, -1) for k in range(3, 7)]
    rows.sort()
    tracks = _tracks(rows)
    tentative = np.array([(r[1] == 10 and r[0] <= 3) for r in rows])
    hist = replace(tracks, tentative=tentative)
    a = association_metrics(hist, truth)
    assert a.delay.tolist() == [3.0, 0.0]
    assert a.delay_mean == 1.5 and a.delay_max == 3.0
    # without the flag every row counts as reported at its scan
    assert association_metrics(tracks, truth).delay.tolist() == [1.0, 0.0]
    # the online view of the history output gives the same delays
    assert association_metrics(hist.online(), truth).delay.tolist() == [3.0, 0.0]
    # a target never matched has no delay; it is left out of the mean
    only_b = tracks.take(tracks.track_id == 20)
    a = association_metrics(only_b, truth)
    assert math.isnan(a.delay[0]) and a.delay[1] == 0.0 and a.delay_mean == 0.0
    d = evaluate(hist, truth).to_dict()
    assert d["delay_mean"] == 1.5 and d["delay_max"] == 3.0 and d["delay"] == [3.0, 0.0]


def test_confirmation_delay_is_that_of_the_online_view():
    """A far track reported all along and a near one tentative at scans 0–2: matched on the
    whole table CLEAR-MOT keeps the near (tentative) track, yet the online view has the far
    track from scan 0, so the delay is 0 in both (reviewer's counter-example)."""
    truth = _truth([(k, 1, 0.0, 0.0) for k in range(6)])
    rows = sorted([(k, 0, 400.0, 0.0, -1) for k in range(6)]
                  + [(k, 1, 10.0, 0.0, -1) for k in range(6)])
    hist = replace(_tracks(rows), tentative=np.array([r[1] == 1 and r[0] <= 2 for r in rows]))
    assert association_metrics(hist, truth).delay.tolist() == [0.0]
    assert association_metrics(hist.online(), truth).delay.tolist() == [0.0]
