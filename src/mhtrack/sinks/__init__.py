"""Sinks: where the tracker's per-frame output goes — a tracks table (CSV/Parquet, at the
end or in rolling parts), a CAT062 recording, or a callback (:mod:`mhtrack.sinks.base`)."""

from mhtrack.sinks.base import CallbackSink, FrameOutput, Sink, TrackCollector
from mhtrack.sinks.files import Cat062Sink, TracksFileSink

__all__ = ["CallbackSink", "Cat062Sink", "FrameOutput", "Sink", "TrackCollector",
           "TracksFileSink"]
