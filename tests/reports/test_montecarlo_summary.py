"""A Monte-Carlo summary keeps the evaluation's parameters apart from its metrics."""

from mhtrack.experiments.montecarlo import MonteCarloResult, MonteCarloSpec
from mhtrack.reports.montecarlo import summary_markdown


def result(tmp_path, cutoffs=(500.0, 500.0)):
    spec = MonteCarloSpec({"name": "tiny"}, ("mht", "mht-agmm"), runs=2, seed=0)
    recs = {t: [{"run": i, "seed": i, "cutoff": c, "order": 2.0, "match_distance": c,
                 "ospa_mean": 10.0 * (i + 1), "scans": [], "ospa": [], "gospa": [],
                 "cardinality": [], "cardinality_true": []}
                for i, c in enumerate(cutoffs)] for t in spec.trackers}
    return MonteCarloResult(spec, tmp_path, recs, {t: {} for t in spec.trackers})


def test_parameters_are_not_metrics(tmp_path):
    res = result(tmp_path)
    assert res.metric_keys() == ["ospa_mean"]
    s = res.summary()["mht"]
    assert s["parameters"] == {"cutoff": 500.0, "order": 2.0, "match_distance": 500.0}
    assert "cutoff" not in s and "cutoff" not in s["std"] and s["ospa_mean"] == 15.0
    md = summary_markdown(res)
    assert "| cutoff |" not in md and "| order |" not in md and "| match_distance |" not in md
    assert ("Parameters: OSPA/GOSPA cut-off c = 500 m, order p = 2, CLEAR-MOT matching "
            "distance = 500 m.") in md
    assert "| ospa_mean | 15 ± 5 | 15 ± 5 |" in md


def test_parameters_that_differ_between_runs_are_listed(tmp_path):
    s = result(tmp_path, cutoffs=(300.0, 500.0)).summary()["mht"]
    assert s["parameters"]["cutoff"] == [300.0, 500.0]
