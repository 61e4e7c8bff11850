"""The paired comparisons of a Monte-Carlo summary: pairs of trackers, verdicts from the
interval, sentences in summary.md."""

from pathlib import Path

from mhtrack.experiments.montecarlo import MonteCarloResult, MonteCarloSpec
from mhtrack.reports.montecarlo import PAIRED_METRICS, paired_comparisons, summary_markdown
from mhtrack.scenario import preset


def _result() -> MonteCarloResult:
    spec = MonteCarloSpec(preset("crossing", scans=5), ("mht", "mht-gmm", "mht-agmm"), runs=6)
    ospa = [100.0, 120.0, 90.0, 110.0, 105.0, 95.0]
    recs = {
        "mht": [{"run": i, "ospa_mean": v + 50.0, "rcc": 0.8} for i, v in enumerate(ospa)],
        "mht-gmm": [{"run": i, "ospa_mean": v, "rcc": 0.9} for i, v in enumerate(ospa)],
        "mht-agmm": [{"run": i, "ospa_mean": v, "rcc": 0.9} for i, v in enumerate(ospa)],
    }
    return MonteCarloResult(spec, Path("."), recs, {t: {} for t in recs})


def test_pairs_and_verdicts() -> None:
    res = _result()
    pairs = paired_comparisons(res)
    keys = [k for k in PAIRED_METRICS if k in ("ospa_mean", "rcc")]
    assert [(c.a, c.b, c.metric) for c in pairs] == [
        (a, b, k) for a, b in (("mht-gmm", "mht"), ("mht-agmm", "mht"),
                               ("mht-agmm", "mht-gmm")) for k in keys]
    by = {(c.a, c.b, c.metric): c for c in pairs}
    # 50 m lower OSPA in every run: better; identical: no detectable difference
    assert by["mht-gmm", "mht", "ospa_mean"].verdict == "better"
    assert by["mht-gmm", "mht", "rcc"].verdict == "better"
    same = by["mht-agmm", "mht-gmm", "ospa_mean"]
    assert same.verdict == "no detectable difference" and same.n_identical == 6
    md = summary_markdown(res)
    assert "## Paired comparisons" in md
    for c in pairs:
        assert c.sentence in md
