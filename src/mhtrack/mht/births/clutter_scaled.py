"""A birth process whose new-target density drops where the clutter map is dense.

:class:`ClutterScaledBirth` wraps any birth process. Its factor on the new-target density
of a plot ``z`` is the clutter map's :func:`~mhtrack.clutter.radar_map.birth_scale`,
``s(z) = min(1, ρ̄/κ̂(z))^β`` (``ρ̄`` the map's mean clutter intensity). The birth score
``ln(s λ_v P_D / (κ̂ + s λ_v))`` (:func:`~mhtrack.mht.scoring.birth_score`) equals the
score the inner process gives with ``κ̂/s`` in place of ``κ̂``,
``ln(λ_v P_D / (κ̂/s + λ_v))`` (multiply numerator and denominator by ``s``), so the inner
process is handed ``κ̂/s``: for ``every-plot`` that is the scaled birth density exactly;
P2's initiators score each plot of a candidate sequence with the ``κ̂`` they are given, so
for them the factor acts on every plot of the sequence. Where the map is no denser than
its mean, or before it has a mean, nothing changes.
"""

from __future__ import annotations

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.radar_map import birth_scale
from mhtrack.mht.births.base import Birth, BirthCandidates
from mhtrack.mht.context import FrameContext
from mhtrack.mht.numbering import Counter
from mhtrack.mht.tree import Leaves


class ClutterScaledBirth(Birth):
    """``inner`` with the birth density scaled by ``s(z)`` (module docstring).

    Parameters
    ----------
    inner : the birth process to wrap.
    clutter : the tracker's clutter estimator (its
        :meth:`~mhtrack.clutter.base.ClutterEstimator.reference_intensity`).
    beta : ``β > 0``, the exponent of the scaling.
    """

    def __init__(self, inner: Birth, clutter: ClutterEstimator, beta: float) -> None:
        if not (np.isfinite(beta) and beta > 0):
            raise ValueError(f"beta must be finite and > 0, got {beta!r}")
        super().__init__(inner.motion)
        self.inner, self.clutter, self.beta = inner, clutter, float(beta)

    def scan_density(self, frame: FrameContext, kappa: np.ndarray) -> float | None:
        """The inner process's new-target density of the frame (e.g. the start-up
        density's), from the unscaled ``κ̂``: the scaling acts on births only."""
        return self.inner.scan_density(frame, kappa)

    def propose(self, frame: FrameContext, kappa: np.ndarray,
                in_gates: np.ndarray | None) -> BirthCandidates:
        s = birth_scale(kappa, self.clutter.reference_intensity(), self.beta)
        return self.inner.propose(frame, np.asarray(kappa, float) / s, in_gates)

    def select(self, frame: FrameContext, cand: BirthCandidates,
               leaf_window: np.ndarray) -> tuple[BirthCandidates, np.ndarray]:
        return self.inner.select(frame, cand, leaf_window)

    def seed(self, frame: FrameContext, cand: BirthCandidates, leaf_window: np.ndarray,
             trees: Counter) -> Leaves:
        return self.inner.seed(frame, cand, leaf_window, trees)

    def limit(self, max_per_scan: int) -> None:
        self.inner.limit(max_per_scan)

    def forget_used(self, window: np.ndarray) -> None:
        self.inner.forget_used(window)

    def arrays(self) -> dict[str, np.ndarray]:
        return self.inner.arrays()

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        self.inner.set_arrays(arrays)
