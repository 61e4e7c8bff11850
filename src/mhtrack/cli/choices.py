"""Transitional: the CLI's choices are :mod:`mhtrack.names`. ``cli/experiment_commands.py``
still imports ``TRACKERS`` from here; delete this module once it imports
``mhtrack.names`` (issue 13 merge)."""

from __future__ import annotations

from mhtrack.names import TRACKERS

__all__ = ["TRACKERS"]
