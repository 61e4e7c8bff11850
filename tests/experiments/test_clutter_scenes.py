"""``reproduce clutter-scenes`` on a tiny study: the oracle's clutter error is 0, every
verdict and interval follows from the per-run records (recomputed here with scipy's t),
the report prints every sentence, the records do not depend on the number of workers,
and an estimator registered by name joins the study."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner
from scipy import stats

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.experiments.clutter_scenes import METRICS, POOLED, clutter_scenes, study_pairs
from mhtrack.experiments.scene_methods import all_methods
from mhtrack.metrics.paired import verdict_of
from mhtrack.reports.clutter_scenes import write_clutter_scenes_report
from mhtrack.scenario import preset

TINY = {"runs": 2, "resolution": 24, "scenes": ("storm",),
        "methods": ("known", "uniform", "gmm")}


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("scenes")
    study = clutter_scenes(out, base=preset("radars-clutter", scans=14), workers=1, **TINY)
    return study


def _strip(rec: dict) -> dict:
    return {k: v for k, v in rec.items() if not k.startswith("t_")}


def test_the_oracle_has_no_clutter_error_and_the_others_have_some(tiny):
    recs = tiny.records["storm"]
    assert not tiny.errors and tiny.computed == 6
    assert [r["iae_mean"] for r in recs["known"]] == [0.0, 0.0]
    assert all(r["iae_mean"] > 0 for m in ("uniform", "gmm") for r in recs[m])
    assert POOLED not in tiny.paired  # one scene: nothing to pool


def test_every_verdict_and_interval_follows_from_the_runs(tiny):
    recs = tiny.records["storm"]
    cs = tiny.paired["storm"]
    assert {(c.a, c.b) for c in cs} == {("gmm", "uniform"), ("known", "gmm")}
    assert {c.metric for c in cs} == set(METRICS)
    for c in cs:
        a = np.array([r[c.metric] for r in recs[c.a]], float)
        b = np.array([r[c.metric] for r in recs[c.b]], float)
        d = a - b
        half = stats.t.ppf(0.975, len(d) - 1) * d.std(ddof=1) / math.sqrt(len(d))
        if half > 0:
            assert (c.ci_low, c.ci_high) == pytest.approx((d.mean() - half, d.mean() + half))
        assert c.verdict == verdict_of(c.ci_low, c.ci_high, c.higher_better)
        assert (f"{c.a} is {c.verdict} than {c.b}" if c.verdict in ("better", "worse")
                else "no detectable difference") in c.sentence
    rep = write_clutter_scenes_report(tiny)
    text = rep.report_path.read_text(encoding="utf-8")
    assert all(c.sentence in text for c in cs)
    res = json.loads(rep.results_path.read_text(encoding="utf-8"))
    assert res["means"]["storm"]["known"]["iae_mean"] == 0.0


def test_same_records_with_two_workers(tiny, tmp_path):
    two = clutter_scenes(tmp_path, base=preset("radars-clutter", scans=14), workers=2, **TINY)
    for m, recs in tiny.records["storm"].items():
        assert [_strip(r) for r in recs] == [_strip(r) for r in two.records["storm"][m]]


class Flat(ClutterEstimator):
    """A constant κ̂ (a stand-in for an estimator registered by another module)."""

    name = "flat"

    def update(self, scan, in_track_gates=None):
        pass

    def intensity(self, z):
        return np.full(len(np.asarray(z).reshape(-1, 2)), 1e-8)

    def get_state(self):
        return {}

    def set_state(self, state):
        pass


def test_an_estimator_registered_by_name_joins_the_study(monkeypatch, tmp_path):
    from mhtrack.build import CLUTTER_ESTIMATOR_CLASSES

    monkeypatch.setitem(CLUTTER_ESTIMATOR_CLASSES, "flat", Flat)
    registered = tuple(n for n in CLUTTER_ESTIMATOR_CLASSES if n != "known")
    assert registered[-1] == "flat"
    assert all_methods() == ("known", "uniform", *registered, "map-birth", "mapgmm-birth")
    assert ("flat", "gmm") in study_pairs(all_methods())
    assert ("flat", "uniform") in study_pairs(all_methods())
    st = clutter_scenes(tmp_path, runs=1, base=preset("radars-clutter", scans=10),
                        scenes=("burst",), methods=("known", "flat"), resolution=16,
                        workers=1)
    (rec,) = st.records["burst"]["flat"]
    assert rec["iae_mean"] > 0 and rec["n_frames"] > 0


def test_cli_writes_the_report(tmp_path):
    from mhtrack.cli.reproduce_commands import reproduce

    out = tmp_path / "cs"
    res = CliRunner().invoke(reproduce, ["clutter-scenes", "--runs", "1", "--scans",
                                    "10", "--scene", "weather", "--method", "known",
                                    "--method", "gmm", "--workers", "1", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "known against gmm: clutter error" in res.output
    assert (out / "report.md").is_file() and (out / "results.json").is_file()
    bad = CliRunner().invoke(reproduce, ["clutter-scenes", "--scene", "fog",
                                    "--out", str(tmp_path / "x")])
    assert bad.exit_code != 0 and "unknown scene(s) fog" in bad.output


def test_a_variant_runs_the_tracker_its_build_gives(tmp_path, monkeypatch):
    """``map-birth`` is built by ``make_tracker`` (its birth wrapper scales the births),
    and ``gmm``'s record is the one of the former path (``mht-gmm``'s tracker given
    ``make_method``'s estimator)."""
    import mhtrack.experiments.scene_methods as sm
    from mhtrack.mht.births.clutter_scaled import ClutterScaledBirth

    calls = []
    real = ClutterScaledBirth.propose

    def propose(self, *a, **k):
        calls.append(1)
        return real(self, *a, **k)

    monkeypatch.setattr(ClutterScaledBirth, "propose", propose)
    base = preset("radars-clutter", scans=10)
    st = clutter_scenes(tmp_path / "new", runs=1, base=base, scenes=("burst",),
                        methods=("gmm", "map-birth"), resolution=16, workers=1)
    assert calls, "map-birth's tracker never used the clutter-scaled birth"
    assert ("map-birth", "map") not in study_pairs(("gmm", "map-birth"))
    assert ("map-birth", "map") in study_pairs(("gmm", "map", "map-birth"))
    monkeypatch.setattr(sm, "has_tracker", lambda m: False)  # the former path
    old = clutter_scenes(tmp_path / "old", runs=1, base=base, scenes=("burst",),
                         methods=("gmm",), resolution=16, workers=1)
    (a,), (b,) = st.records["burst"]["gmm"], old.records["burst"]["gmm"]
    assert _strip(a) == _strip(b)


def test_html_page_holds_every_comparison_and_verdict(tiny):
    """``report.html``: one interval plot per scene, every comparison's sentence and the
    pair summaries, from the same study the Markdown report is written from."""
    pytest.importorskip("plotly")
    import html as html_lib

    from mhtrack.reports.clutter_scenes import pair_summary
    from mhtrack.reports.html_clutter_scenes import write_clutter_scenes_html

    path = write_clutter_scenes_html(tiny)
    text = html_lib.unescape(path.read_text(encoding="utf-8"))
    assert path.name == "report.html" and 'id="fig-paired-storm"' in text
    assert 'id="fig-clutter-error"' in text
    for c in tiny.paired["storm"]:
        assert c.sentence in text
    for line in pair_summary(tiny.paired["storm"]):
        assert line in text


def test_html_without_plotly_fails_before_the_study(tmp_path, monkeypatch):
    """``--html`` without Plotly: the one line and exit 1 of ``report``, before any job
    runs (nothing written under OUT)."""
    import sys

    import mhtrack.experiments.clutter_scenes as cs
    from mhtrack.cli.reproduce_commands import reproduce

    monkeypatch.setitem(sys.modules, "plotly", None)
    ran = []
    monkeypatch.setattr(cs, "clutter_scenes", lambda *a, **k: ran.append(1))
    out = tmp_path / "cs"
    res = CliRunner().invoke(reproduce, ["clutter-scenes", "--runs", "1", "--scans", "10",
                                         "--scene", "weather", "--method", "known",
                                         "--html", "--out", str(out)])
    assert res.exit_code == 1, res.output
    assert res.output.strip().splitlines() == [
        'Error: the HTML report needs Plotly: pip install "mhtrack[report]" '
        "(or pip install plotly)"]
    assert ran == [] and not out.exists()


def test_view_figures_are_those_of_run_scenario_on_the_same_plots(tiny):
    """A job's OSPA, coverage, fragmentations and id switches in each view are those of
    ``run_scenario`` (the path of ``mhtrack run``) with the same tracker, seed and output;
    its tracker CPU time excludes the probe (so it is below the job's wall time)."""
    from mhtrack.experiments.pipeline import run_scenario
    from mhtrack.scenario.scenes import with_clutter_scene

    scenario = with_clutter_scene(preset("radars-clutter", scans=14), "storm")
    rec = tiny.records["storm"]["gmm"][0]
    for view in ("history", "online"):
        s = run_scenario(scenario, rec["seed"], "mht-gmm", output=view, cutoff=500.0,
                         order=2.0).summary()
        assert rec[f"ospa_{view}"] == s["ospa_mean"]
        assert rec[f"coverage_{view}"] == s["coverage"]
        assert rec[f"fragmentations_{view}"] == s["fragmentations"]
        assert rec[f"id_switches_{view}"] == s["id_switches"]
        assert rec[f"ids_{view}"] == s["n_track_ids"]
    assert 0.0 < rec["t_cpu"] < rec["t_run"]
