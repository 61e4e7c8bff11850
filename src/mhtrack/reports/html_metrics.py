"""Metric curves of an HTML report as Plotly figures: OSPA, cardinality and — when the
evaluation has it — OSPA(2) over scans, for one run or a study's mean ± std per tracker.

Input is what :meth:`mhtrack.metrics.Evaluation.to_dict` writes (``metrics.json``) or a
Monte-Carlo summary's ``per_scan`` (:meth:`MonteCarloResult.summary`): per-scan lists
``scans, ospa, cardinality, cardinality_true`` and optionally ``ospa_std``,
``cardinality_std``, ``ospa2`` (and ``ospa2_std``). A panel whose values are all missing
is left out, so OSPA(2) appears as soon as the evaluation computes it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from mhtrack.reports.html_scene import PALETTE

if TYPE_CHECKING:
    import plotly.graph_objects as go

Curves = Mapping[str, Any]

#: Panels in order: (key, y-axis title). ``cardinality`` also draws ``cardinality_true``.
PANELS = (("ospa", "OSPA (m)"), ("ospa2", "OSPA(2) (m)"), ("cardinality", "number of tracks"))


def _values(curve: Curves, key: str) -> np.ndarray | None:
    """``curve[key]`` as floats (``None`` → NaN), or ``None`` when absent, empty, of
    another length than ``scans`` or all missing."""
    raw = curve.get(key)
    if not raw or len(raw) != len(curve.get("scans") or []):
        return None
    v = np.array([np.nan if a is None else a for a in raw], float)
    return v if np.isfinite(v).any() else None


def panels_of(curves: Mapping[str, Curves]) -> list[tuple[str, str]]:
    """The :data:`PANELS` some curve has values for."""
    return [(k, t) for k, t in PANELS if any(_values(c, k) is not None
                                              for c in curves.values())]


def _rgba(hex_color: str, alpha: float) -> str:
    r, g, b = (int(hex_color[i:i + 2], 16) for i in (1, 3, 5))
    return f"rgba({r},{g},{b},{alpha})"


def _band(x: np.ndarray, mean: np.ndarray, std: np.ndarray, color: str,
          name: str) -> dict[str, Any]:
    """mean ± std as one closed filled polygon (upper edge forward, lower edge back)."""
    ok = np.isfinite(mean) & np.isfinite(std)
    xs, lo, hi = x[ok], (mean - std)[ok], (mean + std)[ok]
    return {"type": "scatter", "x": np.concatenate([xs, xs[::-1]]),
            "y": np.concatenate([hi, lo[::-1]]), "fill": "toself", "mode": "lines",
            "line": {"width": 0}, "fillcolor": _rgba(color, 0.15), "hoverinfo": "skip",
            "name": f"{name} ± std", "legendgroup": name, "showlegend": False}


def curves_figure(curves: Mapping[str, Curves], *, cutoff: float | None = None,
                  ospa2_window: int | None = None, title: str = "",
                  x_title: str = "scan") -> go.Figure:
    """OSPA, OSPA(2) (when present) and cardinality per scan, one panel each, x shared;
    one colour per entry of ``curves`` (a label → per-scan lists), mean ± std bands where
    the ``*_std`` lists are given, the true number of targets dashed black (last). The
    x axis and the hover both name the x values ``x_title``."""
    from plotly.subplots import make_subplots

    panels = panels_of(curves)
    titles = []
    for key, _ in panels:
        if key == "ospa":
            titles.append("OSPA per scan" + (f" (c = {cutoff:g} m)" if cutoff else ""))
        elif key == "ospa2":
            titles.append("OSPA(2) per scan" + (f" (window {ospa2_window} scans)"
                                                 if ospa2_window else ""))
        else:
            titles.append("cardinality: tracks reported and true targets")
    fig = make_subplots(rows=max(1, len(panels)), cols=1, shared_xaxes=True,
                        vertical_spacing=0.08, subplot_titles=titles or None)
    true_curve: tuple[np.ndarray, np.ndarray] | None = None
    for j, (label, c) in enumerate(curves.items()):
        color = PALETTE[j % len(PALETTE)]
        x = np.asarray(c.get("scans") or [], float)
        for row, (key, _) in enumerate(panels, start=1):
            y = _values(c, key)
            if y is None:
                continue
            std = _values(c, f"{key}_std")
            if std is not None:
                fig.add_trace(_band(x, y, std, color, label), row=row, col=1)
            fig.add_trace({"type": "scatter", "x": x, "y": y, "mode": "lines",
                           "name": label, "legendgroup": label, "showlegend": row == 1,
                           "line": {"color": color, "width": 1.8},
                           "hovertemplate": f"{label}: %{{y:.4g}} at {x_title} %{{x}}"
                                            "<extra></extra>"}, row=row, col=1)
            true = _values(c, "cardinality_true") if key == "cardinality" else None
            if true is not None and true_curve is None:
                true_curve = (x, true)
    if true_curve is not None:  # last, so that the legend lists the trackers first
        fig.add_trace({"type": "scatter", "x": true_curve[0], "y": true_curve[1],
                       "mode": "lines", "name": "true number of targets",
                       "line": {"color": "black", "width": 1.2, "dash": "dash",
                                "shape": "hvh"}}, row=len(panels), col=1)
    for row, (_, ytitle) in enumerate(panels, start=1):
        fig.update_yaxes(title_text=ytitle, row=row, col=1, rangemode="tozero")
    fig.update_xaxes(title_text=x_title, row=max(1, len(panels)), col=1)
    fig.update_layout(title={"text": title}, height=260 * max(1, len(panels)) + 120,
                      template="plotly_white", hovermode="x unified",
                      legend={"orientation": "h", "y": 1.0, "yanchor": "bottom", "x": 1,
                              "xanchor": "right"},
                      margin={"l": 70, "r": 20, "t": 90, "b": 50})
    return fig


#: Rows of the metrics table: (key, label, unit). Keys absent from the summary are skipped.
METRIC_ROWS: Sequence[tuple[str, str, str]] = (
    ("ospa_mean", "OSPA mean", "m"),
    ("ospa_localisation_mean", "  localisation part", "m"),
    ("ospa_cardinality_mean", "  cardinality part", "m"),
    ("ospa2_mean", "OSPA(2) mean", "m"),
    ("gospa_mean", "GOSPA mean (α = 2)", "m"),
    ("cardinality_error_mean", "cardinality error mean |n̂ − n|", ""),
    ("hota", "HOTA", ""),
    ("deta", "  DetA", ""),
    ("assa", "  AssA", ""),
    ("loca", "  LocA", ""),
    ("mota", "MOTA", ""),
    ("motp", "MOTP (mean matched distance)", "m"),
    ("coverage", "coverage (matched truth states)", ""),
    ("id_switches", "identity switches", ""),
    ("fragmentations", "fragmentations", ""),
    ("n_tracks", "track ids", ""),
    ("n_targets", "targets", ""),
    ("n_matches", "matches", ""),
    ("n_misses", "misses", ""),
    ("n_false", "false track states", ""),
    ("n_truth", "truth states", ""),
    ("rcc", "Rcc (P1 Table 3)", ""),
    ("rmc", "Rmc", ""),
    ("rfg", "Rfg", ""),
    ("l_min", "Lmin (track life)", "s"),
    ("l_avg", "Lavg", "s"),
    ("l_max", "Lmax", "s"),
    ("delay_mean", "confirmation delay mean (scans)", ""),
    ("delay_max", "confirmation delay max (scans)", ""),
    ("t_avg", "tracker time per scan", "s"),
)


def fmt(v: Any, unit: str = "") -> str:
    """A number with 4 significant digits (integers whole), ``–`` when missing."""
    if v is None or isinstance(v, bool):
        return "–" if v is None else str(v)
    if isinstance(v, int):
        return f"{v}{' ' + unit if unit else ''}"
    if not isinstance(v, float) or not np.isfinite(v):
        return "–" if isinstance(v, float) else str(v)
    return f"{v:.4g}{' ' + unit if unit else ''}"


def metric_rows(summary: Mapping[str, Any]) -> list[tuple[str, str]]:
    """``(label, value)`` of every :data:`METRIC_ROWS` key present in ``summary``."""
    return [(label, fmt(summary[k], unit)) for k, label, unit in METRIC_ROWS
            if k in summary and not isinstance(summary[k], list | dict)]
