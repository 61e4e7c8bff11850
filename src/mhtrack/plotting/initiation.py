"""Figures of multi-radar plot fusion and track initiation (P2 Figs. 2, 10–15).

* :func:`clustering_figure` — one panel per clustering method: the scan's plots coloured
  by cluster (marker by radar) and the cluster centres as circles (P2 Fig. 2: random vs
  adaptive initial centres);
* :func:`initiation_figure` — the raw plots of one 4-scan window (P2 Fig. 10), the fused
  plots (Fig. 11), and the tracks each method initiates (Figs. 12–15): true tracks green,
  false ones red (``docs/initiation.md`` for "true");
* :func:`initiated_tracks_figure` — P2 Figs. 12–15 as a 2 × 2 grid.

Drawing only: the data of a run come from :mod:`mhtrack.experiments.initiation_runs`.
Axes zoom on the targets (:func:`zoom_to_truth`: truth box + margin). Figures are
:class:`matplotlib.figure.Figure` objects (no pyplot state, no backend switch); they save
to PNG through the Agg canvas.
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from mhtrack.initiation import FusedScan, InitiatedTracks, Window
from mhtrack.metrics.initiation import track_targets
from mhtrack.plotting.scene import KM_ABOVE_M, set_distance_axes
from mhtrack.plotting.styles import legend_below
from mhtrack.records import Scan

MARKERS = "o^sDvP*X"
SCAN_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:cyan")


def zoom_to_truth(ax: Axes, truth_xy: np.ndarray | None, margin: float = 800.0) -> None:
    """Limit ``ax`` to the box of the truth positions plus ``margin`` (m) on each side."""
    if truth_xy is None or len(truth_xy) == 0:
        return
    lo, hi = truth_xy.min(axis=0) - margin, truth_xy.max(axis=0) + margin
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])


def finish_axes(ax: Axes, title: str) -> None:
    """Equal axes (x east, y north) in metres, or in kilometres when the view spans more
    than :data:`~mhtrack.plotting.scene.KM_ABOVE_M`; a light grid and ``title``."""
    ax.set_aspect("equal", adjustable="box")
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    set_distance_axes(ax, "km" if max(abs(x1 - x0), abs(y1 - y0)) > KM_ABOVE_M else "m")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.set_title(title, fontsize=9)


def _tracks_legend(ax: Axes, fontsize: int) -> None:
    """Legend with the true/false track entries only."""
    handles, labels = ax.get_legend_handles_labels()
    keep = [i for i, lab in enumerate(labels) if "tracks" in lab]
    legend_below(ax, handles=[handles[i] for i in keep],
                 labels=[labels[i] for i in keep], fontsize=fontsize, ncol=2)


def draw_clusters(ax: Axes, scan: Scan, fused: FusedScan) -> None:
    """Plots coloured by cluster, marker by radar; centres as open circles."""
    cmap = matplotlib.colormaps["tab20"]
    radars = np.unique(scan.sensor)
    for r_i, r in enumerate(radars):
        m = scan.sensor == r
        ax.scatter(scan.z[m, 0], scan.z[m, 1], s=14, c=[cmap(v % 20) for v in fused.labels[m]],
                   marker=MARKERS[r_i % len(MARKERS)], lw=0, label=f"radar {r}")
    c = fused.scan.z
    ax.scatter(c[:, 0], c[:, 1], s=120, facecolors="none", edgecolors="k", lw=0.8,
               label=f"{len(c)} cluster centres")


def clustering_figure(scan: Scan, fused: Mapping[str, FusedScan],
                      truth_xy: np.ndarray | None = None, *, title: str = "") -> Figure:
    """One panel per method of ``fused`` (name → :class:`FusedScan` of ``scan``)."""
    n = len(fused)
    fig = Figure(figsize=(6 * n, 5.6))
    axes = fig.subplots(1, n, squeeze=False)
    for ax, (name, f) in zip(axes[0], fused.items(), strict=True):
        draw_clusters(ax, scan, f)
        if truth_xy is not None:
            ax.plot(truth_xy[:, 0], truth_xy[:, 1], "k+", ms=9, label="truth")
        zoom_to_truth(ax, truth_xy)
        finish_axes(ax, f"{name}: k = {f.n_clusters}")
        legend_below(ax, fontsize=7)
    if title:
        fig.suptitle(title)
    return fig


def draw_window(ax: Axes, window: Window, *, clutter_grey: bool = True) -> None:
    """The window's plots, one colour per scan; clutter (origin −1) grey when known."""
    for s in range(window.n_scans):
        r = window.rows(s)
        z = window.z[r]
        col = SCAN_COLOURS[s % len(SCAN_COLOURS)]
        if window.origin is not None and clutter_grey:
            cl = window.origin[r] < 0
            ax.scatter(z[cl, 0], z[cl, 1], s=6, c="0.65", lw=0,
                       label="clutter" if s == 0 else None)
            z = z[~cl]
        ax.scatter(z[:, 0], z[:, 1], s=14, c=col, marker=MARKERS[s % len(MARKERS)], lw=0,
                   label=f"scan {window.scans[s]}")


def draw_tracks(ax: Axes, window: Window, tracks: InitiatedTracks) -> None:
    """Initiated tracks: polylines through their plots; true green, false red."""
    true = (track_targets(tracks.origins(window)) >= 0 if window.origin is not None
            else np.ones(len(tracks), bool))
    for ok in (False, True):  # false first so true tracks are drawn on top
        for row in tracks.flat[true == ok]:
            p = window.z[row[row >= 0]]
            ax.plot(p[:, 0], p[:, 1], "-", color="tab:green" if ok else "tab:red",
                    lw=1.4 if ok else 0.6, alpha=0.9 if ok else 0.5)
    n_true = int(true.sum())
    ax.plot([], [], "-", color="tab:green", label=f"true tracks ({n_true})")
    ax.plot([], [], "-", color="tab:red", label=f"false tracks ({len(tracks) - n_true})")


def initiation_figure(raw: Window, fused: Window, results: Mapping[str, InitiatedTracks],
                      truth_xy: np.ndarray | None = None, *, title: str = "") -> Figure:
    """Raw and fused plots of one window, then one panel per method (P2 Figs. 10–15)."""
    n = 2 + len(results)
    cols = 3
    rows = -(-n // cols)
    fig = Figure(figsize=(5.2 * cols, 5.0 * rows))
    axes = fig.subplots(rows, cols, squeeze=False)
    flat_axes = list(axes.ravel())
    draw_window(flat_axes[0], raw)
    draw_window(flat_axes[1], fused)
    for ax, name in ((flat_axes[0], "plots of the window"), (flat_axes[1], "fused plots")):
        zoom_to_truth(ax, truth_xy)
        finish_axes(ax, name)
        legend_below(ax, fontsize=7, markerscale=1.5)
    for ax, (name, tr) in zip(flat_axes[2:], results.items(), strict=False):
        draw_window(ax, fused)
        draw_tracks(ax, fused, tr)
        zoom_to_truth(ax, truth_xy)
        finish_axes(ax, name)
        _tracks_legend(ax, 7)
    for ax in flat_axes[n:]:
        ax.axis("off")
    if title:
        fig.suptitle(title)
    return fig


def initiated_tracks_figure(window: Window, tracks: Mapping[str, InitiatedTracks],
                            truth_xy: np.ndarray | None, titles: Mapping[str, str], *,
                            title: str = "") -> Figure:
    """P2 Figs. 12–15: the fused window and each method's tracks, one panel per entry of
    ``tracks`` in a 2 × 2 grid, titled ``titles[method]``."""
    fig = Figure(figsize=(11, 10))
    axes = fig.subplots(2, 2)
    for ax, (m, tr) in zip(axes.ravel(), tracks.items(), strict=True):
        draw_window(ax, window)
        draw_tracks(ax, window, tr)
        zoom_to_truth(ax, truth_xy)
        finish_axes(ax, titles[m])
        _tracks_legend(ax, 8)
    if title:
        fig.suptitle(title)
    return fig
