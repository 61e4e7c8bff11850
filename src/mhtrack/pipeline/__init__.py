"""One streaming pipeline from a source to sinks, with every default chosen once.

``source → frames → (fusion) → tracker → sinks``: a :class:`~mhtrack.sources.base.Source`
yields frames in processing order, :class:`Pipeline` builds the tracker for it
(:mod:`.options`: configuration, fusion, clutter frame, birth, output frame) and steps it
frame by frame (:mod:`.run`), handing each frame's output to the sinks
(:mod:`mhtrack.sinks`). :func:`open_input` (:mod:`.inputs`) opens a plots file or a
recording with the sensors file or scenario beside it. The CLI's ``track`` and ``run``
and :func:`mhtrack.experiments.run_scenario` all go through here.
"""

from mhtrack.pipeline.inputs import open_input
from mhtrack.pipeline.options import TrackOptions, birth_density_note
from mhtrack.pipeline.run import (
    Pipeline,
    RunResult,
    cap_scans,
    caps_acted,
    feed,
    fuse_scan,
    fused,
    mean_step_time,
    step_frames,
)

__all__ = ["Pipeline", "RunResult", "TrackOptions", "birth_density_note", "cap_scans",
           "caps_acted", "feed", "fuse_scan", "fused", "mean_step_time", "open_input",
           "step_frames"]
