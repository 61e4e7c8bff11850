"""Multi-radar plot fusion and track initiation (P2; ``docs/initiation.md``).

* :mod:`~mhtrack.initiation.kmeans` — the clustering: standard K-means (P2 §1.1), the
  adaptive initial centres (P2 §1.2), the one-plot-per-radar repair, the merge;
* :mod:`~mhtrack.initiation.fusion` — plot fusion: :class:`AdaptiveKMeansFusion` (P2 §1.2)
  and :class:`KMeansFusion` (random initial centres, P2 §1.1); each ``fuse(scan)`` returns
  a :class:`FusedScan` (one fused plot per cluster);
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

from mhtrack import names as _names
from mhtrack.initiation.fusion import (
    FUSED,
    AdaptiveKMeansFusion,
    FusedScan,
    KMeansFusion,
    fuse_clusters,
    majority_origin,
    split_inconsistent,
)
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

# The name lists live in mhtrack.names, the name -> class mapping in mhtrack.build.
# INITIATORS, FUSIONS and make_initiator stay importable from here only until the MHT's
# initiator birth, experiments/p2, plotting/initiation and cli/initiation_commands import
# them from mhtrack.names / mhtrack.build (issue 13 merge; then delete these lines).
INITIATORS = _names.INITIATORS
FUSIONS = _names.INITIATION_FUSIONS

Initiator = LogicInitiator | HoughInitiator


def make_initiator(method: str, *, theta_deg: float = 20.0, **params: Any) -> Initiator:
    """:func:`mhtrack.build.make_initiator` (transitional, see above)."""
    from mhtrack.build import make_initiator as build_initiator

    return build_initiator(method, theta_deg=theta_deg, **params)


__all__ = [
    "FUSED",
    "FUSIONS",
    "INITIATORS",
    "AdaptiveKMeansFusion",
    "FusedScan",
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
