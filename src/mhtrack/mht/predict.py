"""The predict stage: every leaf to the frame's time with the tracker's motion model."""

from __future__ import annotations

from mhtrack.mht.tree import Leaves
from mhtrack.models.motion import MotionModel, States


def predict_leaves(motion: MotionModel, leaves: Leaves, time: float) -> States:
    """The leaves' states at ``time``, each from its own time ``leaves.time``: ``x⁻, P⁻``
    for gating and misses, per-model arrays for the update. When every leaf has the same
    time (synchronous scans) one interval ``dt`` serves all."""
    states = leaves.states()
    if len(leaves) == 0:
        return states
    dt = float(time) - leaves.time
    if (dt == dt[0]).all():
        return motion.predict(states, float(dt[0]))
    return motion.predict(states, dt)
