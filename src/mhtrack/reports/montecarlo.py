"""The report of a Monte-Carlo study: ``summary.md`` (mean ± std per metric and tracker,
then the paired comparisons of the trackers, :mod:`mhtrack.metrics.paired`) and
``ospa_cardinality.png`` (per-scan OSPA and cardinality, mean ± std over runs)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from mhtrack.experiments.montecarlo import MonteCarloResult
from mhtrack.io.atomic import atomic_write
from mhtrack.plotting.scene import save_figure

SUMMARY_FILE = "summary.md"
FIGURE_FILE = "ospa_cardinality.png"
#: Metrics of the paired comparisons between trackers: key → (higher is better, decimals).
PAIRED_METRICS: dict[str, tuple[bool, int]] = {
    "ospa_mean": (False, 1), "gospa_mean": (False, 1), "rcc": (True, 4),
    "coverage": (True, 4), "mota": (True, 4), "l_avg": (True, 2)}


def paired_comparisons(result: MonteCarloResult) -> list[Any]:
    """Each tracker against each tracker listed before it in the study (candidate A the
    later one), on :data:`PAIRED_METRICS`, paired by run."""
    from mhtrack.metrics.paired import compare_paired, paired_by_run

    trackers = [t for t in result.spec.trackers if result.records.get(t)]
    keys = set(result.metric_keys())
    out = []
    for j, a in enumerate(trackers):
        for b in trackers[:j]:
            for k, (hb, digits) in PAIRED_METRICS.items():
                if k not in keys:
                    continue
                va, vb, _ = paired_by_run(result.records[a], result.records[b], k)
                out.append(compare_paired(va, vb, metric=k, name_a=a, name_b=b,
                                          higher_better=hb, digits=digits))
    return out


def _fmt(v: float) -> str:
    if not math.isfinite(v):
        return "–"
    return f"{v:.4g}"


def summary_markdown(result: MonteCarloResult) -> str:
    """``summary.md``: the evaluation's parameters, then mean ± std per metric (rows) and
    tracker (columns), then the failed and missing runs."""
    s = result.summary()
    spec = result.spec
    lines = [
        f"# Monte-Carlo: {spec.scenario_name}",
        "",
        f"{spec.runs} runs per tracker, base seed {spec.seed}; mean ± std over the "
        "successful runs (population std, NaN ignored).",
        "",
        *_parameters_lines(s, spec.trackers),
        "| metric | " + " | ".join(spec.trackers) + " |",
        "|---|" + "---|" * len(spec.trackers),
    ]
    for k in result.metric_keys():
        cells = [f"{_fmt(s[t][k])} ± {_fmt(s[t]['std'][k])}" for t in spec.trackers]
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    lines.append("| runs ok | " + " | ".join(str(s[t]["n_runs"]) for t in spec.trackers)
                 + " |")
    failed = [(t, i) for t in spec.trackers for i in s[t]["failed"]]
    if failed or result.missing:
        lines += ["", "## Failed runs", ""]
        lines += [f"* {t} run {i}: see `runs/{t}/run-{i}.error.txt`" for t, i in failed]
        lines += [f"* {t} run {i}: not run" for t, i in result.missing]
    pairs = paired_comparisons(result)
    if pairs:
        from mhtrack.reports.paired_text import paired_table, verdict_list

        lines += ["", "## Paired comparisons", "",
                  "Run i of every tracker simulates the same plots: A − B per run, its mean "
                  "with the 95 % t interval, identical runs, sign and Wilcoxon tests; the "
                  "verdict is read from the interval (↑ higher is better, ↓ lower).", "",
                  paired_table(pairs, {k: d for k, (_, d) in PAIRED_METRICS.items()}),
                  verdict_list(pairs).rstrip("\n")]
    return "\n".join(lines) + "\n"


#: How :func:`summary_markdown` names the evaluation's parameters, with their units.
PARAMETER_TEXT = {"cutoff": ("OSPA/GOSPA cut-off c", " m"), "order": ("order p", ""),
                  "match_distance": ("CLEAR-MOT matching distance", " m"),
                  "ospa2_window": ("OSPA(2) window", " scans"),
                  "hota_distance": ("HOTA zero-similarity distance", " m")}


def _parameters_lines(s: dict[str, Any], trackers: tuple[str, ...]) -> list[str]:
    """One line giving the evaluation's parameters (per tracker if they differ)."""
    per = {t: s[t]["parameters"] for t in trackers if s[t]["parameters"]}
    if not per:
        return []

    def text(params: dict[str, Any]) -> str:
        return ", ".join(f"{PARAMETER_TEXT[k][0]} = {v:g}{PARAMETER_TEXT[k][1]}"
                         if not isinstance(v, list) else f"{PARAMETER_TEXT[k][0]} = {v}"
                         for k, v in params.items())

    distinct = {text(p) for p in per.values()}
    if len(distinct) == 1:
        return [f"Parameters: {distinct.pop()}.", ""]
    return ["Parameters:", "", *(f"* {t}: {text(p)}" for t, p in per.items()), ""]


def write_montecarlo_report(result: MonteCarloResult) -> list[Path]:
    """Write ``summary.md`` and (when some run has per-scan curves)
    ``ospa_cardinality.png`` into the study directory; returns the paths written."""
    from mhtrack.plotting.metrics import plot_ospa_cardinality

    out = [atomic_write(result.out_dir / SUMMARY_FILE, summary_markdown(result))]
    curves = {t: v["per_scan"] for t, v in result.summary().items() if v["per_scan"]["scans"]}
    if curves:
        spec = result.spec
        cutoff = spec.run_kwargs.get("cutoff", 500.0)
        title = f"{spec.scenario_name}: mean ± std over {spec.runs} runs"
        out.append(save_figure(plot_ospa_cardinality(curves, cutoff=cutoff, title=title),
                        result.out_dir / FIGURE_FILE, dpi=130))
    return out
