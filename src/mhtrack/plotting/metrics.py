"""Metric curves over scans: OSPA per scan and cardinality (P1 Figs. 5–6).

Figures are :class:`matplotlib.figure.Figure` objects (no pyplot state, no backend
switch); they save to PNG through the Agg canvas."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from mhtrack.plotting.styles import curve_style, legend_outside


def plot_ospa_cardinality(
    runs: Mapping[str, Mapping[str, Sequence[float]]], *, cutoff: float | None = None,
    title: str = "",
) -> Figure:
    """OSPA per scan (top) and estimated vs true cardinality (bottom), one line per entry,
    each with its own line style and markers (:mod:`~mhtrack.plotting.styles`), legends
    outside the axes.

    ``runs`` maps a label (e.g. tracker name) to a mapping with per-scan arrays ``scans``,
    ``ospa``, ``cardinality`` and ``cardinality_true`` — the keys of
    :meth:`mhtrack.metrics.Evaluation.to_dict`. Entries may also hold ``ospa_std`` and
    ``cardinality_std`` (Monte-Carlo spread), drawn as bands.
    """
    fig = Figure(figsize=(9.5, 6.5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    true_drawn = False
    for j, (label, r) in enumerate(runs.items()):
        k = np.asarray(r["scans"])
        ospa = np.asarray(r["ospa"], float)
        style = curve_style(j, len(k), len(runs))
        (line,) = ax1.plot(k, ospa, lw=1.3, label=label, **style)
        if "ospa_std" in r:
            s = np.asarray(r["ospa_std"], float)
            ax1.fill_between(k, ospa - s, ospa + s, color=line.get_color(), alpha=0.15, lw=0)
        card = np.asarray(r["cardinality"], float)
        ax2.plot(k, card, lw=1.3, color=line.get_color(), label=label, **style)
        if "cardinality_std" in r:
            s = np.asarray(r["cardinality_std"], float)
            ax2.fill_between(k, card - s, card + s, color=line.get_color(), alpha=0.15, lw=0)
        if not true_drawn and "cardinality_true" in r:
            ax2.step(k, np.asarray(r["cardinality_true"]), where="mid", color="black", lw=1,
                     ls="--", label="truth")
            true_drawn = True
    ax1.set_ylabel("OSPA (m)" + (f", c = {cutoff:g}" if cutoff else ""))
    ax2.set_ylabel("number of tracks")
    ax2.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax2.set_xlabel("scan")
    for ax in (ax1, ax2):
        ax.grid(True, lw=0.3, alpha=0.5)
        legend_outside(ax)
    if title:
        ax1.set_title(title)
    return fig
