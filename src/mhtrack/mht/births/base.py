"""The birth process of the MHT: which plots start new track trees, and how.

A birth process is a part of the tracker, passed in like the motion model and the clutter
estimator. Every scan the tracker calls, with the frame's context
(:class:`~mhtrack.mht.context.FrameContext`: the validated plots ``z``, ``R``, ``rows``,
the scan, the frame's limits, and :meth:`~mhtrack.mht.context.FrameContext.cut` to count
what a cap removed),

0. :meth:`Birth.scan_density` once the clutter intensity is known (optional hook): the
   frame's new-target density, if the process keeps its own (``None``: the configuration's);
1. :meth:`Birth.propose` after the clutter intensity is known: the candidate new trees'
   first leaves (:class:`BirthCandidates`); their count is reserved in ``max_leaves``;
2. :meth:`Birth.seed` once the existing leaves have grown: the new trees' leaves
   (:meth:`Birth.select` may drop candidates that existing leaves already follow and group
   the rest into trees);
3. :meth:`Birth.forget_used` after the best global hypothesis, with the plots of the
   confirmed tracks (optional hook, a no-op by default).

Before :meth:`Birth.propose` the tracker passes the scan's limit on new trees to
:meth:`Birth.limit` (optional hook).

A process that keeps state across scans saves it through :meth:`Birth.arrays` and
:meth:`Birth.set_arrays` (optional hooks; by default it has none).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from mhtrack.mht.context import FrameContext
from mhtrack.mht.numbering import Counter
from mhtrack.mht.tree import Leaves, new_trees
from mhtrack.models.motion import MotionModel, row_index


@dataclass(frozen=True, slots=True)
class BirthCandidates:
    """New trees' first leaves proposed by a birth process (one row each): state ``x``
    (n, 4), ``P`` (n, 4, 4) at the current scan, ``score`` and ``peak``, ``window``
    (n, width) plot row ids at scans ``k−N … k``, ``n_updates`` (plots on the branch) and
    ``time`` (n,) the states' times (``None``: the scan's time)."""

    x: np.ndarray
    P: np.ndarray
    score: np.ndarray
    peak: np.ndarray
    window: np.ndarray
    n_updates: np.ndarray
    time: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.score.shape[0])

    def take(self, idx: np.ndarray) -> BirthCandidates:
        idx = row_index(idx)
        return BirthCandidates(self.x.take(idx, axis=0), self.P.take(idx, axis=0),
                               self.score.take(idx), self.peak.take(idx),
                               self.window.take(idx, axis=0), self.n_updates.take(idx),
                               None if self.time is None else self.time.take(idx))

    @classmethod
    def empty(cls, width: int) -> BirthCandidates:
        f = np.zeros(0)
        return cls(np.zeros((0, 4)), np.zeros((0, 4, 4)), f, f.copy(),
                   np.zeros((0, width), np.int64), np.zeros(0, np.int64))


class Birth(ABC):
    """A birth process (module docstring). ``motion`` gives new leaves their per-model
    arrays (:meth:`~mhtrack.models.motion.MotionModel.new_states`)."""

    def __init__(self, motion: MotionModel) -> None:
        self.motion = motion

    @abstractmethod
    def propose(self, frame: FrameContext, kappa: np.ndarray,
                in_gates: np.ndarray | None) -> BirthCandidates:
        """Candidate new trees from the frame's plots ``frame.z`` (n, 2), covariances
        ``frame.R`` ((2, 2) or (n, 2, 2)) and row ids ``frame.rows`` (``frame.scan``: the
        scan as given), the clutter intensity ``kappa`` (n,) and the plots in confirmed
        tracks' gates (``None``: no confirmed track). A cap that acts says what it cut
        with ``frame.cut(name, count)``."""

    def select(self, frame: FrameContext, cand: BirthCandidates,
               leaf_window: np.ndarray) -> tuple[BirthCandidates, np.ndarray]:
        """Which candidates start trees, given the grown leaves' windows ``leaf_window``:
        ``(candidates, tree index 0…g−1 of each, ascending)``. Default: all, one tree each."""
        return cand, np.arange(len(cand), dtype=np.int64)

    def seed(self, frame: FrameContext, cand: BirthCandidates, leaf_window: np.ndarray,
             trees: Counter) -> Leaves:
        """The new trees' leaves: :meth:`select`, then consecutive tree ids from ``trees``."""
        cand, group = self.select(frame, cand, leaf_window)
        first = trees.take(int(group.max()) + 1 if len(cand) else 0)
        scan = frame.scan
        time = np.full(len(cand), float(scan.time), float) if cand.time is None else cand.time
        return new_trees(self.motion.new_states(cand.x, cand.P), cand.score, cand.peak,
                         first + group, int(scan.index), cand.n_updates, cand.window, time)

    def scan_density(self, frame: FrameContext, kappa: np.ndarray) -> float | None:
        """Optional hook, called once a frame after the clutter intensity ``kappa`` (n,):
        the frame's new-target density (per m²) that scores its plots and births in place
        of ``MHTConfig.new_target_density`` (e.g. :class:`~mhtrack.mht.undetected.
        UndetectedDensity`'s). Default ``None``: the configuration's."""
        return None

    def limit(self, max_per_scan: int) -> None:  # noqa: B027 (optional hook)
        """Optional hook: the most new trees this scan may start (the scan's
        ``max_births_per_scan``, scaled with the scene by :mod:`mhtrack.mht.caps`).
        Default: nothing (the shipped processes set their ``max_per_scan``)."""

    def forget_used(self, window: np.ndarray) -> None:  # noqa: B027 (optional hook)
        """Optional hook: the leaf windows (m, width) of the confirmed tracks' chosen leaves
        at this scan, whose plots are a target's. Default: nothing."""

    def arrays(self) -> dict[str, np.ndarray]:
        """State to save with the tracker (as ``birth__*`` arrays). Default: none."""
        return {}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:  # noqa: B027 (optional hook)
        """Restore what :meth:`arrays` returned. Default: nothing."""
