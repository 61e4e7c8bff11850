"""Figures of the P1 §3 reproduction: the tracks of run 0 side by side (Fig. 4) and the
per-scan OSPA and cardinality, mean with a ± std band over runs (Figs. 5–6).

Figures are :class:`matplotlib.figure.Figure` objects (no pyplot state, no backend
switch); they save to PNG through the Agg canvas."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from mhtrack.plotting.scene import plot_scene
from mhtrack.plotting.styles import curve_style, legend_outside
from mhtrack.records import TrackTable, TruthTable


def tracks_panels_figure(truth: TruthTable, tracks: Mapping[str, TrackTable | None], *,
                         title: str = "") -> Figure:
    """One panel per entry of ``tracks`` (label → tracks, ``None`` for a failed run): the
    truth and the tracks (P1 Fig. 4)."""
    n = len(tracks)
    fig = Figure(figsize=(5.5 * n, 5.5))
    axes = fig.subplots(1, n, squeeze=False)
    for ax, (label, tr) in zip(axes[0], tracks.items(), strict=True):
        if tr is None:
            ax.text(0.5, 0.5, "run 0 failed", ha="center", va="center", transform=ax.transAxes)
            ax.set_title(label)
            continue
        plot_scene(truth=truth, tracks=tr, ax=ax, title=f"{label} (run 0)")
    if title:
        fig.suptitle(title)
    return fig


def mean_curves_figure(curves: Mapping[str, Mapping[str, Sequence[float]]], key: str, *,
                       ylabel: str, title: str, band_alpha: float,
                       truth_key: str | None = None) -> Figure:
    """Per-scan mean of ``key`` with a ± ``key_std`` band, one line per entry of ``curves``
    (label → per-scan dict with ``scans``, ``key``, ``key_std``), each with its own line
    style and markers (:func:`~mhtrack.plotting.styles.curve_style`, so coinciding curves
    stay visible), legend outside the axes; ``truth_key``: a black dashed step of the first entry's
    true values (P1 Figs. 5–6)."""
    fig = Figure(figsize=(9.5, 4.5))
    ax = fig.subplots()
    true_drawn = truth_key is None
    for j, (label, c) in enumerate(curves.items()):
        k = np.asarray(c["scans"])
        m, sd = np.asarray(c[key], float), np.asarray(c[f"{key}_std"], float)
        (line,) = ax.plot(k, m, lw=1.4, label=label, **curve_style(j, len(k), len(curves)))
        ax.fill_between(k, m - sd, m + sd, color=line.get_color(), alpha=band_alpha, lw=0)
        if not true_drawn:
            ax.step(k, np.asarray(c[truth_key], float), where="mid", color="black",  # type: ignore[index]
                    lw=1.2, ls="--", label="truth")
            true_drawn = True
    ax.set(xlabel="scan", ylabel=ylabel, title=title)
    ax.grid(True, lw=0.3, alpha=0.5)
    legend_outside(ax)
    return fig
