"""Pictures of a scene: truth, plots (clutter grey), tracks and radar sites, in the local
east-north frame, axes in metres or (wide geographic scenes) kilometres.

Follows P1 Figs. 2–4: truth trajectories with ``o`` at the start and ``x`` at the end,
plots as dots (clutter grey, target-originated coloured when ``origin`` is known), tracks
as coloured lines labelled with their id; radar sites as labelled triangles.

Figures are plain :class:`matplotlib.figure.Figure` objects (no pyplot state, no backend
switch on import); :func:`save_figure` writes any figure, a pyplot one included.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib as mpl
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from mhtrack.io.atomic import atomic_path
from mhtrack.plotting.styles import legend_below
from mhtrack.records import PlotTable, TrackTable, TruthTable

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet

TRUTH_STYLE = {"color": "black", "lw": 1.2, "alpha": 0.8}

#: ``units=None`` draws kilometres when the scene's larger side exceeds this (m): beyond
#: 10 km, tick labels of five digits and more (``−12000``) read worse than ``−12``.
KM_ABOVE_M = 10_000.0

#: A radar site to draw: ``(x, y, label)``, local frame (m).
Site = tuple[float, float, str]


def _segments(ids: np.ndarray, scan: np.ndarray) -> list[np.ndarray]:
    """Row indices of each id's trajectory, in scan order."""
    order = np.lexsort((scan, ids))
    ids_sorted = ids[order]
    cuts = np.flatnonzero(np.diff(ids_sorted)) + 1
    return np.split(order, cuts)


def draw_plots(ax: Axes, plots: PlotTable, *, max_points: int = 200_000) -> None:
    """Scatter the plots; clutter grey, target plots in colour when ``origin`` is known."""
    x, y = plots.x, plots.y
    if len(x) > max_points:  # keep huge files drawable; thin deterministically
        keep = np.linspace(0, len(x) - 1, max_points).astype(int)
        x, y = x[keep], y[keep]
        origin = None if plots.origin is None else plots.origin[keep]
    else:
        origin = plots.origin
    if origin is None:
        ax.scatter(x, y, s=2, c="0.55", lw=0, label="plots", rasterized=True)
        return
    clutter = origin < 0
    ax.scatter(x[clutter], y[clutter], s=2, c="0.7", lw=0, label="clutter", rasterized=True)
    ax.scatter(x[~clutter], y[~clutter], s=4, c="tab:blue", lw=0, alpha=0.6,
               label="target plots", rasterized=True)


def draw_truth(ax: Axes, truth: TruthTable) -> None:
    """Truth trajectories: line, ``o`` at birth, ``x`` at death (P1 Fig. 2)."""
    first = True
    for rows in _segments(truth.target_id, truth.scan):
        ax.plot(truth.x[rows], truth.y[rows], **TRUTH_STYLE, label="truth" if first else None)
        ax.plot(truth.x[rows[0]], truth.y[rows[0]], "o", mfc="none", color="black", ms=5)
        ax.plot(truth.x[rows[-1]], truth.y[rows[-1]], "x", color="black", ms=5)
        first = False


def draw_tracks(ax: Axes, tracks: TrackTable, *, label_ids: bool = True) -> None:
    """Tracks as coloured lines, one colour per track id, labelled at their end; rows
    reported only once the track was confirmed (``tentative``, the history output) are
    dotted."""
    cmap = mpl.colormaps["tab10"]
    first = True
    tentative = (np.zeros(len(tracks), bool) if tracks.tentative is None
                 else np.asarray(tracks.tentative, bool))
    for rows in _segments(tracks.track_id, tracks.scan):
        tid = int(tracks.track_id[rows[0]])
        color = cmap(tid % 10)
        tent = np.flatnonzero(tentative[rows])
        if tent.size:  # dotted up to the first confirmed row after the tentative ones
            dotted = rows[: tent[-1] + 2]
            ax.plot(tracks.x[dotted], tracks.y[dotted], ":", color=color, lw=1.4,
                    label="tracks before confirmation" if first else None)
        solid = rows[~tentative[rows]]
        ax.plot(tracks.x[solid], tracks.y[solid], "-", color=color, lw=1.6,
                label="tracks" if first else None)
        if label_ids and len(rows) > 1:
            ax.annotate(str(tid), (tracks.x[rows[-1]], tracks.y[rows[-1]]), color=color,
                        fontsize=7, xytext=(3, 3), textcoords="offset points")
        first = False


def draw_sites(ax: Axes, sites: Sequence[Site]) -> None:
    """Radar sites: a triangle at each ``(x, y)`` (local frame, m), labelled."""
    if not sites:
        return
    xs = [float(s[0]) for s in sites]
    ys = [float(s[1]) for s in sites]
    ax.plot(xs, ys, "^", color="tab:red", mec="black", ms=9, ls="none", zorder=5,
            label="radar sites")
    for x, y, (_, _, label) in zip(xs, ys, sites, strict=True):
        ax.annotate(str(label), (x, y), fontsize=8, xytext=(5, -10),
                    textcoords="offset points", zorder=5)


def sensor_sites(sensors: SensorSet) -> list[Site]:
    """``(x, y, "radar <id>")`` of every sensor of ``sensors`` that has a site, in the
    set's local frame (:meth:`SensorSet.site_xy`)."""
    return [(*sensors.site_xy(s.id), f"radar {s.id}") for s in sensors.sensors if s.has_site]


def scene_units(ax: Axes) -> str:
    """``"km"`` when the data drawn on ``ax`` span more than :data:`KM_ABOVE_M` along x or
    y, else ``"m"``."""
    lim = ax.dataLim
    span = max(lim.width, lim.height)
    return "km" if math.isfinite(span) and span > KM_ABOVE_M else "m"


def set_distance_axes(ax: Axes, units: str) -> None:
    """Label the east/north axes in ``units`` (``"m"`` or ``"km"``); the data stay in
    metres, kilometre tick labels are the metre values / 1000."""
    if units == "m":
        ax.set_xlabel("x east (m)")
        ax.set_ylabel("y north (m)")
        ax.ticklabel_format(style="plain", useOffset=False)
        return
    if units != "km":
        raise ValueError(f"units must be 'm', 'km' or None, got {units!r}")
    minus = "\u2212" if mpl.rcParams["axes.unicode_minus"] else "-"  # as ScalarFormatter
    km = FuncFormatter(lambda v, _pos: f"{v / 1000.0:g}".replace("-", minus))
    ax.xaxis.set_major_formatter(km)
    ax.yaxis.set_major_formatter(km)
    ax.set_xlabel("x east (km)")
    ax.set_ylabel("y north (km)")


def plot_scene(
    plots: PlotTable | None = None,
    truth: TruthTable | None = None,
    tracks: TrackTable | None = None,
    *,
    title: str = "",
    ax: Axes | None = None,
    sites: Sequence[Site] | None = None,
    units: str | None = None,
) -> Figure:
    """One picture of whatever is given: plots, truth, tracks and radar ``sites`` (a list of
    ``(x, y, label)`` in the local frame, e.g. :func:`sensor_sites`), equal axes.

    ``units``: ``"m"``, ``"km"``, or ``None`` — kilometres when the scene spans more than
    10 km (:func:`scene_units`), metres otherwise. The legend sits under the axes, where
    it covers no track (:func:`~mhtrack.plotting.styles.legend_below`). Draws on a new
    :class:`~matplotlib.figure.Figure` (or on ``ax``), never on pyplot's state."""
    if units not in (None, "m", "km"):
        raise ValueError(f"units must be 'm', 'km' or None, got {units!r}")
    if ax is None:
        fig = Figure(figsize=(7.5, 8))
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    if plots is not None and len(plots):
        draw_plots(ax, plots)
    if truth is not None and len(truth):
        draw_truth(ax, truth)
    if tracks is not None and len(tracks):
        draw_tracks(ax, tracks)
    if sites:
        draw_sites(ax, sites)
    ax.set_aspect("equal", adjustable="datalim")
    set_distance_axes(ax, scene_units(ax) if units is None else units)
    ax.grid(True, lw=0.3, alpha=0.5)
    if title:
        ax.set_title(title)
    legend_below(ax, markerscale=3)
    return fig


def save_figure(fig: Figure, path: str | Path, *, dpi: int = 130,
                tight: bool = True) -> Path:
    """Write ``fig`` to ``path`` (format from the extension; PNG by the Agg canvas, whatever
    the interactive backend) after a tight layout (``tight``), atomically, and release it."""
    path = Path(path)
    if tight:
        fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi)
    close_figure(fig)
    return path


def close_figure(fig: Figure) -> None:
    """Release ``fig``: a figure made by pyplot is closed there (a plain ``Figure`` holds
    nothing beyond its own references). Does not import pyplot."""
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close(fig)
