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
* :mod:`~mhtrack.initiation.runs` — simulate, fuse and initiate over many seeds (what the
  CLI commands ``cluster`` and ``initiate`` call).
"""

from __future__ import annotations

from typing import Any

from mhtrack.initiation.base import Fuser, Initiator
from mhtrack.initiation.fused import FUSED, FusedScan, fuse_clusters, majority_origin
from mhtrack.initiation.fusion import AdaptiveKMeansFusion, KMeansFusion, split_inconsistent
from mhtrack.initiation.hough import HoughInitiator
from mhtrack.initiation.kmeans import (
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

#: Initiation methods by CLI name.
INITIATORS: tuple[str, ...] = ("logic", "modified-logic", "hough", "modified-hough")
#: Fusion methods by CLI name.
FUSIONS: tuple[str, ...] = ("adaptive-kmeans", "kmeans", "none")


def make_initiator(method: str, *, theta_deg: float = 20.0, **params: Any) -> Initiator:
    """The initiator named ``method`` (:data:`INITIATORS`); ``theta_deg`` is P2's angle
    limit for the modified methods (ignored by the plain ones); ``params`` go to the
    constructor (e.g. ``gate_radius``, ``v_min``, ``v_max``)."""
    if method == "logic":
        return LogicInitiator(angle_limit_deg=None, **params)
    if method == "modified-logic":
        return LogicInitiator(angle_limit_deg=theta_deg, **params)
    if method == "hough":
        return HoughInitiator(modified=False, angle_limit_deg=theta_deg, **params)
    if method == "modified-hough":
        return HoughInitiator(modified=True, angle_limit_deg=theta_deg, **params)
    raise ValueError(f"unknown initiation method {method!r} (expected {', '.join(INITIATORS)})")


__all__ = [
    "FUSED",
    "FUSIONS",
    "INITIATORS",
    "AdaptiveKMeansFusion",
    "FusedScan",
    "Fuser",
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
    "make_initiator",
    "merge_compatible_clusters",
    "remove_dominated",
    "sliding_windows",
    "sorted_distances",
    "split_inconsistent",
]
