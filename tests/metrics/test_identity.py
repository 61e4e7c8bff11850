"""Identity figures (issue 29 item 7) on a constructed run where each is worked by hand."""

import json
import math

import numpy as np

from mhtrack.attributes import PlotAttributes
from mhtrack.metrics import evaluate
from mhtrack.metrics.identity import IDENTITY_KEYS, dominant_targets, target_identities
from mhtrack.records import PlotTable, TrackTable, TruthTable

# Two targets at rest, scans 0..3 every 10 s: target 1 at (0, 0), target 2 at (10 km, 0).
TRUTH = TruthTable(
    scan=np.array([0, 0, 1, 1, 2, 2, 3, 3]), time=np.repeat([0.0, 10, 20, 30], 2),
    target_id=np.tile([1, 2], 4), x=np.tile([0.0, 10_000], 4), y=np.zeros(8),
    vx=np.zeros(8), vy=np.zeros(8))
# Plots: (scan, origin, code, garbled, address); codes 1234 / 4321 (octal).
_P = [(0, 1, 0o1234, 0, 0xAAAAAA), (0, 2, 0o4321, 0, 0xBBBBBB), (1, 2, 0o4321, 0, 0xBBBBBB),
      (2, 1, 0o1235, 1, -1), (2, 2, 0o4321, 0, -1), (3, 2, 0o4321, 0, 0xBBBBBB),
      (3, 2, -1, 0, -1)]
_s = np.array([p[0] for p in _P])
PLOTS = PlotTable(
    scan=_s, time=10.0 * _s, sensor=np.zeros(7, np.int64), x=np.zeros(7), y=np.zeros(7),
    origin=np.array([p[1] for p in _P]),
    attrs=PlotAttributes.from_columns({
        "mode_3a": np.array([p[2] for p in _P]), "mode_3a_g": np.array([p[3] for p in _P]),
        "address": np.array([p[4] for p in _P])}))
# Tracks: 7 on target 1 (50 m off) at scans 0-1 (coasting at 1); 8 on target 1 at scan 2
# and 3 km off at scan 3 with target 2's plot; 9 on target 2 throughout; 5 false.
_T = [(0, 7, 30.0, 40.0, 0), (1, 7, 30.0, 40.0, -1), (2, 8, 0.0, 0.0, 3),
      (3, 8, 3000.0, 0.0, 5), (0, 9, 10_000.0, 0.0, 1), (1, 9, 10_000.0, 0.0, 2),
      (2, 9, 10_000.0, 0.0, 4), (3, 9, 10_000.0, 0.0, 6), (1, 5, 50_000.0, 0.0, -1)]
_order = np.lexsort(([t[1] for t in _T], [t[0] for t in _T]))
TRACKS = TrackTable(
    scan=np.array([t[0] for t in _T])[_order], time=10.0 * np.array([t[0] for t in _T])[_order],
    track_id=np.array([t[1] for t in _T])[_order], x=np.array([t[2] for t in _T])[_order],
    y=np.array([t[3] for t in _T])[_order], vx=np.zeros(9), vy=np.zeros(9),
    plot=np.array([t[4] for t in _T])[_order])


def test_hand_worked_figures():
    ev = evaluate(TRACKS, TRUTH, plots=PLOTS, identity=True)
    i = ev.identity
    assert ev.at == "scans" and ev.clear_mot.n_matches == 7  # the matching worked below
    # target 1 ← tracks 7 (scans 0, 1) and 8 (scan 2); target 2 ← track 9: (2 + 1) / 2
    assert i.ids_per_aircraft == 1.5
    # rows with a comparable code/address: 7@0, 8@3 (4321 ≠ 1234), 9@0, 9@1, 9@2; 8@2's
    # plot is garbled without address, 9@3's plot primary: 1 wrong of 5
    assert (i.n_code_rows, i.wrong_code_rate) == (5, 0.2)
    # matched distances 50, 50, 0 × 5
    assert math.isclose(i.rms_horizontal, math.sqrt(2 * 50**2 / 7))
    # default T: plot gaps of target 1 (20 s) and 2 (10, 10, 10, 0 s) → median of > 0 is 10;
    # target 1 updated at 0, 20, 30 s → intervals {0, 2} of 3; target 2 all 3 → 5 / 6
    assert i.update_interval == 10.0 and math.isclose(i.p_update, 5 / 6)
    # 9 track states, 7 matched: 8@3 (3 km) and the false track 5; both have no target
    # within the match distance (500 m): false, none multiple
    assert math.isclose(i.extra_track_rate, 2 / 9)
    assert math.isclose(i.false_track_rate, 2 / 9) and i.multiple_track_rate == 0.0
    # tracks with a dominant target: 7, 8, 9; track 8 is 3 km > 1 NM from target 1 at scan 3
    assert math.isclose(i.dubious_track_rate, 1 / 3)


def test_options_and_parts():
    assert dominant_targets(evaluate(TRACKS, TRUTH).clear_mot.matching) == {7: 1, 8: 1, 9: 2}
    assert target_identities(PLOTS) == {1: (0o1234, 0xAAAAAA), 2: (0o4321, 0xBBBBBB)}
    i = evaluate(TRACKS, TRUTH, plots=PLOTS, identity=True, update_interval=30.0,
                 dubious_distance=5000.0).identity
    # T = 30 s: one interval [0, 30] per target, both updated; no state 5 km off
    assert (i.p_update, i.dubious_track_rate) == (1.0, 0.0)
    # no plots: no codes; T the truth's step (10 s) as with the plots
    j = evaluate(TRACKS, TRUTH, identity=True).identity
    assert math.isnan(j.wrong_code_rate) and j.n_code_rows == 0
    assert j.update_interval == 10.0 and math.isclose(j.p_update, 5 / 6)


def test_keys_only_when_asked():
    plain = evaluate(TRACKS, TRUTH, plots=PLOTS).to_dict()
    asked = evaluate(TRACKS, TRUTH, plots=PLOTS, identity=True)
    d = asked.to_dict()
    assert not set(IDENTITY_KEYS) & set(plain)
    assert {k: v for k, v in d.items() if k not in IDENTITY_KEYS} == plain
    assert json.loads(json.dumps(d))["wrong_code_rate"] == 0.2
    assert "ids per aircraft" in asked.to_table()
    assert "ids per aircraft" not in evaluate(TRACKS, TRUTH).to_table()


def test_cli_identity_flag(tmp_path):
    """``evaluate --identity`` end to end: simulated plots with attributes, tracked; the
    JSON's identity keys equal the library's on the same files, and without the flag the
    JSON has none of them."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli
    from mhtrack.io import read_plots, read_tracks, read_truth

    def run(*args: str) -> str:
        r = CliRunner().invoke(cli, [str(a) for a in args])
        assert r.exit_code == 0, r.stderr
        return r.stdout

    run("simulate", "crossing", "--seed", "1", "--attributes", "--out", tmp_path)
    plots, truth, tracks = (tmp_path / f for f in ("plots.csv", "truth.csv", "tracks.csv"))
    run("track", plots, "--out", tracks)
    d = json.loads(run("evaluate", tracks, truth, "--plots", plots, "--identity", "--json"))
    pl = read_plots(plots)
    lib = evaluate(read_tracks(tracks, plots=pl), read_truth(truth), plots=pl, identity=True)
    assert {k: d[k] for k in IDENTITY_KEYS} == json.loads(json.dumps(
        {k: lib.to_dict()[k] for k in IDENTITY_KEYS}))
    assert d["n_code_rows"] > 0 and 0 <= d["wrong_code_rate"] <= 1
    plain = json.loads(run("evaluate", tracks, truth, "--plots", plots, "--json"))
    assert not set(IDENTITY_KEYS) & set(plain)
    r = CliRunner().invoke(cli, ["evaluate", str(tracks), str(truth), "--update-interval",
                                 "4"])
    assert r.exit_code != 0 and "--identity" in r.stderr


def test_a_second_track_on_a_target_is_multiple():
    """Track 6 at scan 2, 100 m from target 1, which track 8 holds there: one multiple
    state of 10; 8@3 and track 5 stay false."""
    extra = TrackTable(scan=np.array([2]), time=np.array([20.0]), track_id=np.array([6]),
                       x=np.array([100.0]), y=np.array([0.0]), vx=np.zeros(1),
                       vy=np.zeros(1), plot=np.array([-1]))
    both = TrackTable.concat([TRACKS, extra])
    order = np.lexsort((both.track_id, both.scan))
    i = evaluate(both.take(order), TRUTH, identity=True).identity
    assert math.isclose(i.extra_track_rate, 3 / 10)
    assert math.isclose(i.multiple_track_rate, 1 / 10)
    assert math.isclose(i.false_track_rate, 2 / 10)
