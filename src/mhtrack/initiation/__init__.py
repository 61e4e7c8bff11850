"""Multi-radar plot fusion and track initiation (P2; ``docs/initiation.md``).

* :mod:`~mhtrack.initiation.base` — the parts' interfaces: :class:`Fuser` (``fit`` →
  ``fuse(scan)``) and :class:`Initiator` (``find_tracks`` → the one ``initiate(window)``);
* :mod:`~mhtrack.initiation.kmeans` — the clustering: standard K-means (P2 §1.1), the
  adaptive initial centres (P2 §1.2), the one-plot-per-radar repair, the merge;
* :mod:`~mhtrack.initiation.fused` — the fused output: :class:`FusedScan` (one fused plot
  per cluster), :func:`fuse_clusters`, :func:`majority_origin`;
* :mod:`~mhtrack.initiation.fusion` — the fusers :class:`AdaptiveKMeansFusion` (P2 §1.2)
  and :class:`KMeansFusion` (random initial centres, P2 §1.1);
* :mod:`~mhtrack.initiation.window` — sliding windows of ``N`` scans, the
  :class:`InitiatedTracks` record, least-squares initial states;
* :mod:`~mhtrack.initiation.logic` — :class:`LogicInitiator` (3/4 logic, and the modified
  logic with the angle constraint, P2 §2.1);
* :mod:`~mhtrack.initiation.hough` — :class:`HoughInitiator` (plain and modified Hough);

Simulating, fusing and initiating over many seeds (the CLI's ``cluster`` and ``initiate``)
is an experiment: :mod:`mhtrack.experiments.initiation_runs`. Initiators and fusers are
built by name with :func:`mhtrack.build.make_initiator`; the names are in
:mod:`mhtrack.names`.
"""

from __future__ import annotations

from mhtrack.initiation.base import Fuser, Initiator
from mhtrack.initiation.fused import FUSED, FusedScan, fuse_clusters, majority_origin
from mhtrack.initiation.fusion import AdaptiveKMeansFusion, KMeansFusion, split_inconsistent
from mhtrack.initiation.hough import HoughInitiator
from mhtrack.initiation.kmeans import (
    Gate,
    adaptive_initial_centres,
    dissimilarity_threshold,
    enforce_one_plot_per_sensor,
    kmeans_lloyd,
    merge_compatible_clusters,
    sorted_distances,
)
from mhtrack.initiation.logic import LogicInitiator, leg_angle
from mhtrack.initiation.window import (
    InitiatedTracks,
    Window,
    least_squares_state,
    remove_dominated,
    sliding_windows,
)

__all__ = [
    "FUSED",
    "AdaptiveKMeansFusion",
    "FusedScan",
    "Fuser",
    "Gate",
    "HoughInitiator",
    "InitiatedTracks",
    "Initiator",
    "KMeansFusion",
    "LogicInitiator",
    "Window",
    "adaptive_initial_centres",
    "dissimilarity_threshold",
    "enforce_one_plot_per_sensor",
    "fuse_clusters",
    "kmeans_lloyd",
    "least_squares_state",
    "leg_angle",
    "majority_origin",
    "merge_compatible_clusters",
    "remove_dominated",
    "sliding_windows",
    "sorted_distances",
    "split_inconsistent",
]
