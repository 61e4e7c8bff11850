"""True and estimated clutter intensity side by side (``mhtrack clutter``'s figure)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from mhtrack.models.clutter import Region
from mhtrack.plotting.scene import save_figure


def plot_intensity_maps(
    true: np.ndarray,
    estimated: np.ndarray,
    region: Region,
    *,
    plots: np.ndarray | None = None,
    titles: tuple[str, str] = ("true κ", "estimated κ̂"),
    title: str = "",
    dynamic_range: float = 1e4,
) -> Figure:
    """Two maps of intensities on the ``n × n`` grid of ``region`` (rows = y, as
    :meth:`Region.grid` orders them), on one logarithmic colour scale spanning
    ``dynamic_range`` below the larger maximum (values under it drawn as the lowest
    colour). ``plots`` (m, 2), e.g. the scan's plots, are drawn on both maps."""
    true = np.asarray(true, float)
    estimated = np.asarray(estimated, float)
    if true.shape != estimated.shape or true.ndim != 2:
        raise ValueError(f"maps must be equal 2-D grids, got {true.shape} and {estimated.shape}")
    vmax = float(max(true.max(), estimated.max(), 1e-300))
    norm = LogNorm(vmin=vmax / dynamic_range, vmax=vmax)
    fig = Figure(figsize=(12, 5.4), layout="constrained")
    axes = fig.subplots(1, 2, sharex=True, sharey=True)
    extent = region.as_tuple()
    im = None
    for ax, grid, name in zip(axes, (true, estimated), titles, strict=True):
        im = ax.imshow(np.clip(grid, vmax / dynamic_range, None), origin="lower",
                       extent=extent, norm=norm, cmap="magma", interpolation="nearest")
        if plots is not None and len(plots):
            ax.scatter(plots[:, 0], plots[:, 1], s=6, facecolors="none", edgecolors="cyan",
                       lw=0.6, label="plots")
        ax.set_title(name)
        ax.set_xlabel("x east (m)")
        ax.set_aspect("equal")
        ax.ticklabel_format(style="plain", useOffset=False)
    axes[0].set_ylabel("y north (m)")
    assert im is not None
    fig.colorbar(im, ax=list(axes), shrink=0.85, label="plots per m² per scan")
    if title:
        fig.suptitle(title)
    return fig


def save_maps(fig: Figure, path: str | Path, *, dpi: int = 130) -> Path:
    """Write the figure of :func:`plot_intensity_maps` (its layout is already set) and
    close it."""
    return save_figure(fig, path, dpi=dpi, tight=False)
