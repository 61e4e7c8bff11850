"""The HTML page of ``reproduce clutter-scenes --html`` (``OUT/report.html``): the paired
comparisons pooled over the scenes and per scene as interval plots (Plotly, through
:func:`~mhtrack.reports.html_study.paired_figure`) and tables, the verdict sentences, each
scene's means per method with the clutter error drawn per method, and the study's
parameters. Everything comes from the study's records and comparisons
(:class:`~mhtrack.experiments.clutter_scenes.ClutterScenesStudy`), as ``report.md``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mhtrack.experiments.clutter_scenes import METRICS, POOLED, ClutterScenesStudy
from mhtrack.io.atomic import atomic_write
from mhtrack.reports.clutter_scenes import TIMES, method_means, pair_summary
from mhtrack.reports.html_page import Page, require_plotly
from mhtrack.reports.html_study import plain

if TYPE_CHECKING:
    import plotly.graph_objects as go

HTML_FILE = "report.html"


def _rows(comparisons: Any) -> list[dict[str, Any]]:
    """The comparisons as plain dicts, the metric by its label (NaN as ``None``)."""
    return [{**plain(c), "metric": METRICS[c.metric][0]} for c in comparisons]


def error_figure(study: ClutterScenesStudy) -> go.Figure:
    """Clutter error per method (mean over runs, bar ± one std), one group per scene."""
    import numpy as np
    import plotly.graph_objects as go

    fig = go.Figure()
    scenes = list(study.records)
    methods = list(dict.fromkeys(m for by in study.records.values() for m in by))
    for m in methods:
        vals = [[r["iae_mean"] for r in study.records[s].get(m, [])] for s in scenes]
        fig.add_trace(go.Bar(name=m, x=scenes,
                             y=[float(np.mean(v)) if v else None for v in vals],
                             error_y={"type": "data", "array": [float(np.std(v)) if v else 0.0
                                                                for v in vals]}))
    fig.update_layout(barmode="group", template="plotly_white", height=420,
                      yaxis_title="clutter error ∫|κ̂ − κ| (plots/rotation)",
                      margin={"l": 70, "r": 20, "t": 30, "b": 40})
    return fig


def clutter_scenes_page(study: ClutterScenesStudy) -> Page:
    """The page (module docstring)."""
    from mhtrack.reports.html_study import paired_figure, paired_table

    require_plotly()
    p = study.params
    page = Page(f"mhtrack reproduce clutter-scenes: {p['runs']} paired runs per scene",
                f"{p['base']}; scenes {', '.join(p['scenes'])}; base seed {p['seed']}")
    means = method_means(study)
    order = [POOLED, *[s for s in study.paired if s != POOLED]]
    for scene in (s for s in order if s in study.paired):
        cs = study.paired[scene]
        page.section(f"Paired comparisons: {scene}")
        page.note("Run i of every method tracks the same simulated plots: A − B per run, "
                  "its mean and 95 % t interval; green: A better, red: A worse, grey: no "
                  "detectable difference (the verdict read from the interval).")
        rows = _rows(cs)
        if rows:
            page.figure(paired_figure(rows), f"paired-{scene.replace(' ', '-')}")
            page.table(*paired_table(rows, {lab: d for lab, _, d in METRICS.values()}))
        page.sentences(pair_summary(cs))
        page.sentences([c.sentence for c in cs])
        if scene in means:
            keys = list(METRICS)
            page.table(["method", "runs", *(METRICS[k][0] for k in keys),
                        "estimator (ms/frame)"],
                       [[m, str(int(r["n_runs"])),
                         *(f"{r[k]:.{METRICS[k][2]}f}" for k in keys),
                         f"{1e3 * r[TIMES[2]]:.3f}"] for m, r in means[scene].items()])
    page.section("Clutter error per scene and method")
    page.figure(error_figure(study), "clutter-error")
    page.section("Parameters")
    page.table(None, [(k, json.dumps(v, sort_keys=True, ensure_ascii=False)
                        if not isinstance(v, str) else v) for k, v in p.items()],
               numbers=False)
    if study.errors:
        page.sentences([f"failed or missing: {k}" for k in sorted(study.errors)])
    return page


def write_clutter_scenes_html(study: ClutterScenesStudy, plotlyjs: str = "inline") -> Path:
    """Write ``report.html`` into the study's folder, atomically; its path."""
    return atomic_write(Path(study.out_dir) / HTML_FILE,
                        clutter_scenes_page(study).render(plotlyjs))
