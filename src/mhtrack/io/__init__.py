"""File input and output: plots, truth and tracks tables (CSV or Parquet, chosen by the
file extension) and TOML scenario files, validated at the boundary.

Every problem with a user's file raises :class:`InputError` with a message naming the
file, the line (CSV, header = line 1) or 0-based row (Parquet), and the column. The file
formats are described in ``docs/file-formats.md``.
"""

from mhtrack.errors import InputError
from mhtrack.io.plots import read_plots, write_plots
from mhtrack.io.tomlfile import read_toml, write_scenario_toml
from mhtrack.io.tracks import read_tracks, tracks_from_truth, write_tracks
from mhtrack.io.truth import read_truth, write_truth

__all__ = [
    "InputError",
    "read_plots",
    "read_toml",
    "read_tracks",
    "read_truth",
    "tracks_from_truth",
    "write_plots",
    "write_scenario_toml",
    "write_tracks",
    "write_truth",
]
