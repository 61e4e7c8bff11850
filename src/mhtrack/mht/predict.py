"""The predict stage: every leaf to the scan time with the tracker's motion model."""

from __future__ import annotations

from mhtrack.mht.tree import Leaves
from mhtrack.models.motion import MotionModel, States


def predict_leaves(motion: MotionModel, leaves: Leaves, dt: float | None) -> States:
    """The leaves' states ``dt`` seconds after the last scan (``None``: the first scan,
    nothing to predict): ``x⁻, P⁻`` for gating, per-model arrays for the update."""
    states = leaves.states()
    if len(leaves) == 0 or dt is None:
        return states
    return motion.predict(states, dt)
