"""Saving a report's figures: atomically, in the format of the file's extension."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from mhtrack.io.atomic import atomic_path


def save(fig: Figure, path: str | Path, *, dpi: int, tight: bool = True) -> Path:
    """Write ``fig`` to ``path`` atomically (``tight``: ``tight_layout`` first)."""
    if tight:
        fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi)
    return Path(path)
