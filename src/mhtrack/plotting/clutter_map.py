"""The clutter map of each radar over time: one row per radar, one column per time, each
cell of range and bearing coloured by its intensity (per km² per look, log scale)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from mhtrack.clutter.radar_map import MapSnapshot


def plot_clutter_maps(snapshots: Sequence[Mapping[int, MapSnapshot]], *,
                      title: str | None = None, names: Mapping[int, str] | None = None
                      ) -> Figure:
    """``snapshots[t][radar]``: the maps at each time (columns) of each radar (rows); a
    radar missing at a time leaves its panel empty. One colour scale for the whole figure
    (the positive intensities' range, in plots per km² per look)."""
    radars = sorted({i for s in snapshots for i in s})
    n_r, n_t = max(len(radars), 1), max(len(snapshots), 1)
    fig = Figure(figsize=(3.2 * n_t + 1.0, 3.0 * n_r))
    vals = [1e6 * m.intensity[m.intensity > 0] for s in snapshots for m in s.values()]
    pos = np.concatenate(vals) if vals else np.zeros(0)
    norm = (LogNorm(vmin=max(float(pos.min()), float(pos.max()) * 1e-4), vmax=float(pos.max()))
            if pos.size else None)
    mesh = None
    for row, rid in enumerate(radars):
        for col, snap in enumerate(snapshots):
            ax = fig.add_subplot(n_r, n_t, row * n_t + col + 1)
            ax.set_aspect("equal")
            ax.tick_params(labelsize=7)
            m = snap.get(rid)
            if m is None:
                ax.set_axis_off()
                continue
            x, y = m.edges()
            k = np.ma.masked_less_equal(1e6 * m.intensity, 0.0)
            mesh = ax.pcolormesh(x / 1e3, y / 1e3, k, norm=norm, cmap="viridis",
                                 shading="flat")
            label = (names or {}).get(rid, f"radar {rid}")
            ax.set_title(f"{label}, t = {m.time:.0f} s", fontsize=8)
            if col == 0:
                ax.set_ylabel("north (km)", fontsize=8)
            if row == n_r - 1:
                ax.set_xlabel("east (km)", fontsize=8)
    fig.subplots_adjust(left=0.07, right=0.86, bottom=0.08, top=0.9, wspace=0.3,
                        hspace=0.35)
    if mesh is not None:
        cax = fig.add_axes((0.89, 0.15, 0.02, 0.7))
        fig.colorbar(mesh, cax=cax, label="clutter per km² per look")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig
