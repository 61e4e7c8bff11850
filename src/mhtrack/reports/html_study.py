"""The study part of an HTML report (a Monte-Carlo directory): mean ± std per tracker and
metric, and the paired comparisons of the trackers with their confidence intervals.

Paired comparisons come from, in order: the Monte-Carlo report's
``paired_comparisons(result)`` when this installation has it (module
:mod:`mhtrack.reports.montecarlo`, built on ``mhtrack.metrics.paired``); else a
``"paired"`` list in a JSON file of the directory (``results.json``, ``table3.json``: the
fields of ``PairedComparison.to_dict()``); else none, and the page shows the per-tracker
table only. A comparison is ``a − b`` per run: its mean difference with the 95 % t
interval, and the verdict read from the interval (``mhtrack.metrics.paired``).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mhtrack.io.atomic import is_temporary
from mhtrack.reports.html_metrics import METRIC_ROWS, fmt

if TYPE_CHECKING:
    import plotly.graph_objects as go

    from mhtrack.experiments.montecarlo import MonteCarloResult

#: Fields a paired comparison needs to be drawn.
PAIRED_FIELDS = ("metric", "a", "b", "n", "mean_diff", "ci_low", "ci_high")
VERDICT_COLORS = {"better": "#2ca02c", "worse": "#d62728"}
NEUTRAL = "#7f7f7f"
#: Keys of a summary that repeat another one (``n_track_ids`` is ``n_tracks``).
SAME_AS = {"n_track_ids": "n_tracks"}


def tracker_table(result: MonteCarloResult) -> tuple[list[str], list[list[str]]]:
    """Header and rows ``[metric, mean ± std per tracker…]`` of a study, the metrics of
    :data:`~mhtrack.reports.html_metrics.METRIC_ROWS` first, then any other, then the
    number of successful runs."""
    s = result.summary()
    trackers = list(result.spec.trackers)
    labels = {k: (label, unit) for k, label, unit in METRIC_ROWS}
    labels["n_scans"] = ("scans evaluated", "")
    keys = [k for k in result.metric_keys() if k not in SAME_AS]
    ordered = [k for k, _, _ in METRIC_ROWS if k in keys] + [k for k in keys if k not in labels]
    rows = []
    for k in ordered:
        label, unit = labels.get(k, (k, ""))
        rows.append([label] + [f"{fmt(s[t][k])} ± {fmt(s[t]['std'][k])}{' ' + unit if unit else ''}"
                               for t in trackers])
    rows.append(["successful runs"] + [str(s[t]["n_runs"]) for t in trackers])
    return ["metric", *trackers], rows


def plain(c: Any) -> dict[str, Any]:
    """A comparison (or a mapping) as a plain dict, NaN and infinities as ``None`` (JSON)."""
    d = c.to_dict() if hasattr(c, "to_dict") else dict(c)
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
            for k, v in d.items()}


def _valid(rows: Sequence[Any]) -> list[dict[str, Any]]:
    out = []
    for r in rows:
        if isinstance(r, Mapping) and all(f in r for f in PAIRED_FIELDS):
            out.append(plain(r))
    return out


def paired_from_json(directory: Path) -> tuple[list[dict[str, Any]], str | None]:
    """The ``"paired"`` list of the first JSON file in ``directory`` (sorted by name) that
    has one, and that file's name; ``([], None)`` if none."""
    for path in sorted(p for p in directory.glob("*.json") if not is_temporary(p)):
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        rows = data.get("paired") if isinstance(data, dict) else None
        if isinstance(rows, list) and (valid := _valid(rows)):
            return valid, path.name
    return [], None


def paired_rows(result: MonteCarloResult | None, directory: Path
                ) -> tuple[list[dict[str, Any]], str | None]:
    """The study's paired comparisons as plain dicts and where they come from (module
    docstring); ``([], None)`` when there are none."""
    if result is not None:
        from mhtrack.reports import montecarlo

        compute = getattr(montecarlo, "paired_comparisons", None)
        if compute is not None:
            rows = _valid([plain(c) for c in compute(result)])
            if rows:
                return rows, "mhtrack.metrics.paired on the runs"
    return paired_from_json(directory)


def paired_table(rows: Sequence[Mapping[str, Any]], digits: Mapping[str, int] | None = None
                 ) -> tuple[list[str], list[list[str]]]:
    """Header and rows of the paired comparisons: metric, A, B, n, mean A − B, 95 % CI,
    verdict; the difference and its bounds as the text reports print them
    (:func:`~mhtrack.metrics.paired.difference_texts`, ``digits`` decimals per metric,
    default 3)."""
    from mhtrack.metrics.paired import difference_texts

    def num(v: Any) -> float:
        return math.nan if v is None else float(v)

    out = []
    for r in rows:
        mean, lo, hi = difference_texts(num(r["mean_diff"]), num(r["ci_low"]),
                                        num(r["ci_high"]), (digits or {}).get(r["metric"], 3))
        ci = (f"[{lo}, {hi}]" if r["ci_low"] is not None and r["ci_high"] is not None
              else "–")
        arrow = {True: " ↑", False: " ↓"}.get(r.get("higher_better"), "")
        out.append([f"{r['metric']}{arrow}", str(r["a"]), str(r["b"]), str(r["n"]),
                    mean, ci, str(r.get("verdict", ""))])
    return ["metric", "A", "B", "runs", "mean A − B", "95 % CI", "verdict"], out


def paired_figure(rows: Sequence[Mapping[str, Any]], title: str = "") -> go.Figure:
    """One panel per metric: each comparison ``A − B`` as its mean difference with the
    95 % interval as error bar, a vertical line at 0, green when A is better, red when
    worse, grey when no difference is detectable (the verdict of the interval)."""
    from plotly.subplots import make_subplots

    metrics = list(dict.fromkeys(str(r["metric"]) for r in rows))
    n_pairs = max((sum(r["metric"] == m for r in rows) for m in metrics), default=1)
    height = len(metrics) * (110 + 30 * n_pairs) + 80  # px; 70 px between panels
    fig = make_subplots(rows=len(metrics), cols=1, subplot_titles=[
        m + {True: " (higher is better)", False: " (lower is better)"}.get(
            next((r.get("higher_better") for r in rows if r["metric"] == m), None), "")
        for m in metrics], vertical_spacing=70 / height if len(metrics) > 1 else 0.0)
    for i, m in enumerate(metrics, start=1):
        sel = [r for r in rows if r["metric"] == m]
        x = [math.nan if r["mean_diff"] is None else r["mean_diff"] for r in sel]
        lo = [0.0 if r["ci_low"] is None or r["mean_diff"] is None
              else r["mean_diff"] - r["ci_low"] for r in sel]
        hi = [0.0 if r["ci_high"] is None or r["mean_diff"] is None
              else r["ci_high"] - r["mean_diff"] for r in sel]
        fig.add_trace({"type": "scatter", "mode": "markers", "x": x,
                       "y": [f"{r['a']} − {r['b']}" for r in sel],
                       "error_x": {"type": "data", "symmetric": False, "array": hi,
                                   "arrayminus": lo, "color": "#444", "thickness": 1.5},
                       "marker": {"size": 10, "color": [VERDICT_COLORS.get(
                           str(r.get("verdict")), NEUTRAL) for r in sel]},
                       "text": [str(r.get("sentence") or r.get("verdict", "")) for r in sel],
                       "hovertemplate": "%{text}<extra></extra>", "name": m,
                       "showlegend": False}, row=i, col=1)
        fig.add_vline(x=0, line={"color": "black", "width": 1, "dash": "dot"}, row=i, col=1)
    fig.update_layout(title={"text": title}, template="plotly_white", height=height,
                      margin={"l": 160, "r": 20, "t": 70, "b": 40})
    return fig
