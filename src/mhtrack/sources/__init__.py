"""Sources: plots from a table, a recording or a network feed, yielded frame by frame in
time order (:mod:`mhtrack.sources.base`)."""

from mhtrack.sources.base import Source, SourceStats, Survey

__all__ = ["Source", "SourceStats", "Survey"]
