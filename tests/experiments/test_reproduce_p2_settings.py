"""``reproduce p2 --tracker-settings paper|best`` and ``--clutter-per``: the jobs carry the
options only when not the default, the scenario's λ reading, the paired comparisons."""

import numpy as np
import pytest

from mhtrack.experiments.p2.aggregate import PAIRS, paired_methods
from mhtrack.experiments.p2.jobs import _initiators, job_scenario, make_jobs, p2_scenario
from mhtrack.names import INITIATORS


def test_default_jobs_keep_their_parameters():
    """Default (best, λ per radar) jobs hold no new key: their hashes do not change."""
    for j in make_jobs(2, 0, [20.0], [20.0], [50.0]):
        assert "settings" not in j.params and "clutter_per" not in j.params
    for j in make_jobs(2, 0, [20.0], [20.0], [50.0], settings="paper", clutter_per="scan"):
        assert j.params["settings"] == "paper" and j.params["clutter_per"] == "scan"


def test_clutter_per_scan_spreads_lambda_over_the_radars():
    per_radar = job_scenario({"sigma": 20.0, "rate": 90.0})
    per_scan = job_scenario({"sigma": 20.0, "rate": 90.0, "clutter_per": "scan"})
    n = len(per_radar.sensors)
    assert n == 3
    assert per_scan.clutter_rate(per_scan.first) * n == pytest.approx(
        per_radar.clutter_rate(per_radar.first))


def test_paper_settings_switch_on_the_acceleration_constraint():
    region = p2_scenario().region.as_tuple()
    assert _initiators(region)["modified-hough"].accel_max is None
    assert _initiators(region, "paper")["modified-hough"].accel_max == 150.0
    assert _initiators(region, "paper")["hough"].accel_max is None


def test_paired_methods_hand_example():
    # rows [found, false, tracks, n_targets, n_windows]; modified-logic has 2 false
    # tracks per window fewer than logic in each of 3 runs
    per_run = {m: [[5, 10, 15, 10, 5]] * 3 for m in INITIATORS}
    per_run["modified-logic"] = [[5, 0, 5, 10, 5], [4, 0, 4, 10, 5], [5, 0, 5, 10, 5]]
    out = paired_methods(per_run)
    assert len(out) == 2 * len(PAIRS)
    c = next(x for x in out if x["a"] == "modified-logic" and x["b"] == "logic"
             and x["metric"] == "false_per_window")
    assert c["mean_diff"] == pytest.approx(-2.0) and c["n"] == 3 and c["n_a_better"] == 3
    p = next(x for x in out if x["a"] == "modified-logic" and x["b"] == "logic"
             and x["metric"] == "p_true")
    assert p["mean_diff"] == pytest.approx(np.mean([0.0, -0.1, 0.0]))
    assert p["n_identical"] == 2


def test_ablation_one_run():
    from mhtrack.experiments.p2.ablation import ablation

    res = ablation(1)
    assert len(res) == 6
    for m in res.values():
        assert 0.0 <= m["p_true"] <= 1.0 and 0.0 <= m["p_false"] <= 1.0
        assert m["tracks_per_window"] >= m["false_per_window"] >= 0.0


def test_bad_settings_are_refused(tmp_path):
    from click.testing import CliRunner

    from mhtrack.cli.reproduce_commands import reproduce
    from mhtrack.experiments.p2 import reproduce_p2

    with pytest.raises(ValueError, match="settings"):
        reproduce_p2(tmp_path, 1, settings="fastest")
    with pytest.raises(ValueError, match="clutter_per"):
        reproduce_p2(tmp_path, 1, clutter_per="sensor")
    r = CliRunner().invoke(reproduce, ["p2", "--out", str(tmp_path), "--tracker-settings",
                                       "fastest"])
    assert r.exit_code == 2 and "fastest" in r.output


@pytest.mark.parametrize("settings", ["paper", "best"])
def test_example_figures_use_the_settings_of_the_study(settings):
    """Figs. 12–15 show what the study's jobs run: the example's fused window and tracks
    equal those of ``fused_run`` and ``_initiators`` with the same settings (and Fig. 2's
    adaptive panel is the fusion of those settings, under its honest label)."""
    from mhtrack.experiments.jobs import run_seed
    from mhtrack.experiments.p2.constants import ADAPTIVE_LABELS, FUSION_PARAMS
    from mhtrack.experiments.p2.examples import fig2_example, fig12_15_example
    from mhtrack.experiments.p2.jobs import fused_run
    from mhtrack.initiation import Window
    from mhtrack.initiation.fusion import AdaptiveKMeansFusion

    ex = fig12_15_example(0, settings)
    sc = p2_scenario()
    _raw, win = next(fused_run(sc, run_seed(0, 0, "words"), settings).windows(4))
    w = Window.from_scans(win)
    np.testing.assert_array_equal(ex.fused.z, w.z)
    inits = _initiators(sc.region.as_tuple(), settings)
    for m, tracks in ex.tracks.items():
        np.testing.assert_array_equal(tracks.origins(ex.fused), inits[m].initiate(w).origins(w))
    f2 = fig2_example(0, settings)
    assert ADAPTIVE_LABELS[settings] in f2.fused
    ref = AdaptiveKMeansFusion(**FUSION_PARAMS[settings]).fuse(f2.scan)
    np.testing.assert_array_equal(f2.fused[ADAPTIVE_LABELS[settings]].scan.z, ref.scan.z)


def test_paper_and_best_fusions_differ_somewhere():
    """The settings change the fused plots (otherwise the test above could not fail on a
    mix-up): on the first run at the nominal setting some fused scan differs."""
    from mhtrack.experiments.jobs import run_seed
    from mhtrack.experiments.p2.jobs import fused_run

    sc = p2_scenario()
    a = fused_run(sc, run_seed(0, 0, "words"), "paper").fused
    b = fused_run(sc, run_seed(0, 0, "words"), "best").fused
    assert any(len(x.z) != len(y.z) or not np.array_equal(x.z, y.z)
               for x, y in zip(a, b, strict=True))
