"""``clutter_maps.png``: each radar's clutter map over time
(:func:`mhtrack.plotting.clutter_map.plot_clutter_maps`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from mhtrack.clutter.radar_map import MapSnapshot
from mhtrack.plotting.clutter_map import plot_clutter_maps
from mhtrack.plotting.scene import save_figure

FIGURE_FILE = "clutter_maps.png"


def write_clutter_maps(out_dir: str | Path, snapshots: Sequence[Mapping[int, MapSnapshot]],
                       *, title: str | None = None,
                       names: Mapping[int, str] | None = None) -> Path:
    """Draw the maps (one row per radar, one column per time) to ``out_dir/``
    :data:`FIGURE_FILE` (written atomically by :func:`save_figure`)."""
    fig = plot_clutter_maps(snapshots, title=title, names=names)
    return save_figure(fig, Path(out_dir) / FIGURE_FILE, tight=False)
