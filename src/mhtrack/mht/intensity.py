"""The clutter stage: feed the estimator the scan, then read ``κ̂(z)`` at its plots."""

from __future__ import annotations

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.mht.context import FrameContext


def clutter_intensity(clutter: ClutterEstimator, frame: FrameContext,
                      in_gates: np.ndarray | None, floor: float) -> np.ndarray:
    """:meth:`~mhtrack.clutter.base.ClutterEstimator.update` with the frame's scan and the
    plots in confirmed tracks' gates, then ``max(κ̂(z), floor)`` of every plot ``z`` of
    the frame (the floor keeps a score finite where a density estimate underflows;
    ``MHTConfig.min_clutter_density``).
    Raises ``ValueError`` when the estimator returns anything but finite values ≥ 0."""
    scan, z = frame.scan, frame.z
    clutter.update(scan, in_gates)
    kappa = np.asarray(clutter.intensity(z), dtype=float).reshape(-1)
    if kappa.shape != (len(z),) or not np.isfinite(kappa).all() or (kappa < 0).any():
        raise ValueError(
            f"scan {scan.index}: clutter estimator {clutter.name!r} returned an "
            f"invalid intensity (need {len(z)} finite values >= 0)"
        )
    return np.maximum(kappa, floor)
