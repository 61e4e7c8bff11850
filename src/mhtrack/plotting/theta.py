"""Curves against the angle limit θ (P2 Figs. 3–4: p_true and p_false of the modified
3/4 logic for several range errors or clutter rates).

Figures are :class:`matplotlib.figure.Figure` objects (no pyplot state, no backend
switch); they save to PNG through the Agg canvas."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from mhtrack.plotting.styles import curve_style, legend_outside


def theta_curves_figure(thetas_deg: Sequence[float], curves: Mapping[str, Sequence[float]],
                        *, ylabel: str, title: str, theta_mark: float | None = None,
                        mark_label: str = "") -> Figure:
    """One line per entry of ``curves`` (label → value per θ of ``thetas_deg``, NaN where
    undefined), θ sorted, on a [0, 1] axis, each with its own line style and marker,
    legend outside the axes; a dotted vertical line at ``theta_mark``."""
    th = np.asarray(thetas_deg, float)
    o = np.argsort(th)
    fig = Figure(figsize=(8.5, 4.6))
    ax = fig.subplots()
    for j, (label, v) in enumerate(curves.items()):
        style = {**curve_style(j, len(th), len(curves)), "markevery": None, "ms": 3.5}
        ax.plot(th[o], np.asarray(v, float)[o], label=label, **style)
    if theta_mark is not None:
        ax.axvline(theta_mark, color="0.6", ls=":", lw=1, label=mark_label or None)
    ax.set_xlabel("angle limit θ (deg)")
    ax.set_ylabel(ylabel)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xticks(np.arange(0, 181, 20))
    ax.grid(alpha=0.3)
    legend_outside(ax)
    ax.set_title(title, fontsize=10)
    return fig
