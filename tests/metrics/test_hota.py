"""HOTA against a hand-worked example and against trackeval (the reference code of
Luiten et al. 2021) on constructed and simulated runs."""

import numpy as np
import pytest

from mhtrack.metrics.hota import ALPHAS, hota, similarity


@pytest.fixture(autouse=True)
def _numpy_aliases_for_trackeval(monkeypatch):
    """The numpy aliases (np.float, np.int, np.bool) that older trackeval code uses, for
    the duration of each test here only (never in the library; 1.3.0 does not need them)."""
    for name, alias in (("float", float), ("int", int), ("bool", bool)):
        if not hasattr(np, name):
            monkeypatch.setattr(np, name, alias, raising=False)


def _trackeval_hota():
    """trackeval's HOTA metric object."""
    metrics = pytest.importorskip("trackeval.metrics",
                                  reason="trackeval not installed (pip install -e '.[reference]')")
    return metrics.HOTA()


def _trackeval_data(tracks, truth, d_max):
    """trackeval's per-sequence data dict for point targets, S = max(0, 1 − d/d_max)."""
    scans = np.union1d(truth.scan, tracks.scan)
    gt_u, tr_u = np.unique(truth.target_id), np.unique(tracks.track_id)
    data = {"gt_ids": [], "tracker_ids": [], "similarity_scores": []}
    for k in scans:
        g = truth.scan == k
        t = tracks.scan == k
        X, Y = truth.positions[g], tracks.positions[t]
        d = np.hypot(X[:, None, 0] - Y[None, :, 0], X[:, None, 1] - Y[None, :, 1])
        data["gt_ids"].append(np.searchsorted(gt_u, truth.target_id[g]))
        data["tracker_ids"].append(np.searchsorted(tr_u, tracks.track_id[t]))
        data["similarity_scores"].append(np.maximum(0.0, 1.0 - d / d_max))
    data.update(num_gt_dets=len(truth), num_tracker_dets=len(tracks), num_gt_ids=len(gt_u),
                num_tracker_ids=len(tr_u), num_timesteps=len(scans))
    return data


def _check_against_trackeval(tracks, truth, d_max):
    ref = _trackeval_hota().eval_sequence(_trackeval_data(tracks, truth, d_max))
    ours = hota(tracks, truth, d_max)
    for field, arr in (("HOTA", ours.hota_alpha), ("DetA", ours.deta_alpha),
                       ("AssA", ours.assa_alpha), ("LocA", ours.loca_alpha),
                       ("DetRe", ours.detre_alpha), ("DetPr", ours.detpr_alpha),
                       ("AssRe", ours.assre_alpha), ("AssPr", ours.asspr_alpha)):
        np.testing.assert_allclose(arr, ref[field], atol=1e-6, rtol=0, err_msg=field)
    assert ours.hota == pytest.approx(float(np.mean(ref["HOTA"])), abs=1e-6)
    assert ours.hota > 0 or ref["HOTA"].max() == 0
    return ours


def test_alphas_are_the_papers():
    np.testing.assert_allclose(ALPHAS, np.linspace(0.05, 0.95, 19))


def test_similarity_mapping():
    np.testing.assert_allclose(similarity(np.array([0.0, 50.0, 100.0, 300.0]), 100.0),
                               [1.0, 0.5, 0.0, 0.0])


def test_hand_worked_constant_offset(make_truth, make_tracks):
    # One target, one track 30 m away at every scan, d_max = 100: S = 0.7 everywhere.
    # α ≤ 0.7 (14 of the 19 thresholds): every pair a TP, DetA = AssA = 1, HOTA_α = 1,
    # LocA_α = 0.7. α > 0.7: no TP, HOTA_α = 0, LocA_α = 1 (trackeval's convention).
    truth = make_truth([(k, 1, 10.0 * k, 0.0) for k in range(5)])
    tracks = make_tracks([(k, 7, 10.0 * k, 30.0) for k in range(5)])
    r = hota(tracks, truth, 100.0)
    assert r.hota == pytest.approx(14 / 19)
    assert r.deta == pytest.approx(14 / 19)
    assert r.assa == pytest.approx(14 / 19)
    assert r.loca == pytest.approx((14 * 0.7 + 5 * 1.0) / 19)


def test_hand_worked_identity_switch(make_truth, make_tracks):
    # One target for 4 scans, exact positions; track id 1 at scans 0-1, id 2 at scans 2-3.
    # Every α: TP = 4, DetA = 1; each TP's association: TPA = 2, FNA = 2, FPA = 0 → 1/2;
    # AssA = 1/2, HOTA = √(1/2).
    truth = make_truth([(k, 1, 0.0, 0.0) for k in range(4)])
    tracks = make_tracks([(0, 1, 0, 0), (1, 1, 0, 0), (2, 2, 0, 0), (3, 2, 0, 0)])
    r = hota(tracks, truth, 100.0)
    assert (r.deta, r.assa, r.loca) == pytest.approx((1.0, 0.5, 1.0))
    assert r.hota == pytest.approx(np.sqrt(0.5))


def test_constructed_perfect(make_truth, make_tracks):
    truth = make_truth([(k, i, 100.0 * i, 5.0 * k) for k in range(6) for i in range(3)])
    tracks = make_tracks([(k, 10 + i, 100.0 * i, 5.0 * k) for k in range(6) for i in range(3)])
    r = _check_against_trackeval(tracks, truth, 50.0)
    assert r.hota == pytest.approx(1.0)


def test_constructed_switch_false_and_missed(make_truth, make_tracks):
    # two crossing targets whose tracks swap ids mid-way, a false track, a missed scan
    truth = make_truth([(k, i, 20.0 * k, 100.0 * i) for k in range(8) for i in range(2)])
    rows = []
    for k in range(8):
        for i in range(2):
            if (k, i) == (3, 1):
                continue  # missed
            tid = 5 + (i if k < 4 else 1 - i)
            rows.append((k, tid, 20.0 * k + 7 * i, 100.0 * i + 11.0 * (k % 3)))
        if k in (2, 3, 4):
            rows.append((k, 99, 500.0, 500.0))
    _check_against_trackeval(make_tracks(rows), truth, 60.0)


def test_constructed_fragments_and_empty_scans(make_truth, make_tracks):
    # a target tracked by three fragments with growing errors, scans without truth
    truth = make_truth([(k, 3, 0.0, 10.0 * k) for k in range(10)])
    rows = [(k, 1 + k // 4, 3.0 * k, 10.0 * k) for k in range(10) if k != 5]
    rows += [(12, 40, 0.0, 0.0), (13, 40, 0.0, 5.0)]
    _check_against_trackeval(make_tracks(rows), truth, 40.0)


def test_constructed_no_tracks_and_no_truth(make_truth, make_tracks):
    truth = make_truth([(0, 1, 0.0, 0.0), (1, 1, 0.0, 0.0)])
    empty_tracks = make_tracks([])
    r = _check_against_trackeval(empty_tracks, truth, 50.0)
    assert (r.hota, r.loca) == (0.0, 1.0)
    assert r.fn.tolist() == [2.0] * 19
    r = _check_against_trackeval(make_tracks([(0, 1, 0.0, 0.0)]), make_truth([]), 50.0)
    assert r.fp.tolist() == [1.0] * 19


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_runs_against_trackeval(random_run, seed):
    truth, tracks = random_run(seed)
    _check_against_trackeval(tracks, truth, 300.0)


def test_simulated_mht_run_against_trackeval():
    from mhtrack.build import default_config, make_tracker
    from mhtrack.records import PlotTable
    from mhtrack.scenario import preset, simulate

    sim = simulate(preset("crossing"), seed=1)
    plots = PlotTable.from_scans([s for s in sim.plots.scans() if s.index < 40])
    tracks = make_tracker("mht-agmm", default_config(sim.scenario)).run(plots)
    truth = sim.truth
    truth = type(truth)(*(getattr(truth, f)[truth.scan < 40]
                          for f in truth.__dataclass_fields__))
    r = _check_against_trackeval(tracks, truth, 500.0)
    assert 0.3 < r.hota < 1.0


def test_in_evaluate(random_run):
    from mhtrack.metrics import evaluate

    truth, tracks = random_run(3)
    ev = evaluate(tracks, truth, cutoff=300.0)
    d = ev.to_dict()
    r = hota(tracks, truth, 300.0)  # d_max defaults to the cut-off
    assert (d["hota"], d["deta"], d["assa"], d["loca"], d["hota_distance"]) == pytest.approx(
        (r.hota, r.deta, r.assa, r.loca, 300.0))
    assert evaluate(tracks, truth, hota_distance=100.0).hota.hota == pytest.approx(
        hota(tracks, truth, 100.0).hota)


def test_cli_evaluate_json_shows_hota_and_ospa2(tmp_path):
    # the truth of a simulated run scored as tracks: perfect, HOTA = DetA = AssA = LocA = 1
    import csv
    import json

    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    r = CliRunner().invoke(cli, ["simulate", "crossing", "--seed", "1", "--scans", "20",
                                 "--out", str(tmp_path)])
    assert r.exit_code == 0, r.stderr
    tracks = tmp_path / "tracks.csv"
    with (tmp_path / "truth.csv").open() as f, tracks.open("w", newline="") as g:
        w = csv.writer(g)
        w.writerow(["scan", "time", "track_id", "x", "y", "vx", "vy", "plot"])
        for row in csv.DictReader(f):
            w.writerow([row[k] for k in ("scan", "time", "target_id", "x", "y", "vx", "vy")]
                       + [""])
    r = CliRunner().invoke(cli, ["evaluate", str(tracks), str(tmp_path / "truth.csv"),
                                 "--json"])
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    assert (d["hota"], d["deta"], d["assa"], d["loca"]) == (1.0, 1.0, 1.0, 1.0)
    assert d["hota_distance"] == d["cutoff"] and d["ospa2_window"] == 10
    assert d["ospa2_mean"] == 0.0 and d["ospa2"] == [0.0] * d["n_scans"]
