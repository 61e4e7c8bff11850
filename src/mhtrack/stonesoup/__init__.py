"""mhtrack inside Stone Soup: its MHT as a Stone Soup ``Tracker`` and converters between
Stone Soup's detections, ground truth and tracks and mhtrack's tables.

Needs the optional extra: ``pip install "mhtrack[stonesoup]"``.

* :class:`MHTrackTracker` — a Stone Soup tracker (detector in, ``(time, set[Track])``
  out) running :func:`mhtrack.build.make_tracker`'s MHT;
* :func:`detections_to_xy`, :func:`detections_to_plots` — detections (``LinearGaussian``,
  ``CartesianToBearingRange``, ``CartesianToElevationBearingRange``) → plots with their
  own ``R``;
* :func:`ground_truth_to_table`, :func:`table_to_tracks`, :func:`tracks_to_table` —
  ground truth and tracks between the two libraries.
"""

try:
    import stonesoup  # noqa: F401
except ImportError:  # pragma: no cover - depends on the environment
    raise ImportError('mhtrack.stonesoup needs Stone Soup: pip install "mhtrack[stonesoup]"'
                      ) from None

from mhtrack.stonesoup.convert import (
    POSITION_MAPPING,
    VELOCITY_MAPPING,
    detections_to_plots,
    detections_to_xy,
    ground_truth_to_table,
    table_to_tracks,
    tracks_to_table,
)
from mhtrack.stonesoup.tracker import MHTrackTracker

__all__ = [
    "POSITION_MAPPING",
    "VELOCITY_MAPPING",
    "MHTrackTracker",
    "detections_to_plots",
    "detections_to_xy",
    "ground_truth_to_table",
    "table_to_tracks",
    "tracks_to_table",
]
