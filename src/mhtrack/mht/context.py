"""The context of one frame through the tracking cycle (:meth:`MHTTracker.step`).

A :class:`FrameContext` is made once per frame, after the scan is validated, and handed to
the stages that need more than their own arrays: the frame's validated plots ``z``, their
covariances ``R`` and row ids ``rows``, the limits scaled to the frame
(:func:`mhtrack.mht.caps.scan_config`), and the counters of the hard caps that acted
(:meth:`FrameContext.cut`), which :class:`~mhtrack.mht.report.StepStats` reports. A
stage that cuts says so through it; nothing else of the frame changes after it is made.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mhtrack.mht.caps import SCALED, scan_config, scene_leaves
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.identity import Reported
from mhtrack.records import Scan


@dataclass(slots=True, eq=False)
class FrameContext:
    """One frame's context (module docstring).

    ``scan`` the frame as given; ``z`` (n, 2), ``R`` ((2, 2) or (n, 2, 2)) and ``rows``
    (n,) its plots as :func:`~mhtrack.mht.validate.validate_scan` returns them;
    ``limits`` the configuration with this frame's scaled limits; ``scene_leaves`` the
    leaves the frame supports (:func:`mhtrack.mht.caps.scene_leaves`; ``None``: the
    overload rule is off); ``previous`` the tracks reported at the previous frame (for
    the hand-over; ``None``: not known); ``caps`` each hard cap that acted → what it cut.
    """

    scan: Scan
    z: np.ndarray
    R: np.ndarray
    rows: np.ndarray
    limits: MHTConfig = field(default_factory=MHTConfig)
    scene_leaves: int | None = None
    previous: Reported | None = None
    caps: dict[str, int] = field(default_factory=dict)

    @classmethod
    def of(cls, scan: Scan, plots: tuple[np.ndarray, np.ndarray, np.ndarray], *,
           config: MHTConfig, previous: Reported, n_sensors: int = 1) -> FrameContext:
        """The context of ``scan`` with its validated ``plots`` ``(z, R, rows)``, entered
        with the tracks ``previous`` reported: the limits of ``config`` scaled to its
        plots and those tracks, ``max_trees``' floor to the ``n_sensors`` whose frames
        the store holds (:mod:`mhtrack.mht.caps`)."""
        z, R, rows = plots
        n_tracks = len(previous.track)
        return cls(scan, z, R, rows, scan_config(config, len(z), n_tracks, n_sensors),
                   scene_leaves(config, len(z), n_tracks), previous)

    @property
    def time(self) -> float:
        """The frame's time (s): every plot's, or the latest plot time of timed plots."""
        return float(self.scan.time)

    @property
    def index(self) -> int:
        """The frame's scan index."""
        return int(self.scan.index)

    @property
    def t(self) -> np.ndarray | None:
        """(n,) each plot's own time (``None``: the frame's :attr:`time`)."""
        return self.scan.t

    @property
    def n_plots(self) -> int:
        return len(self.z)

    def scaled_limits(self) -> dict[str, int]:
        """The limits that scale with the scene and their values in this frame."""
        return {k: getattr(self.limits, k) for k in SCALED}

    def cut(self, cap: str, count: int) -> None:
        """Record that ``cap`` cut ``count`` leaves, trees, plots or clusters (added to
        what it cut earlier in the frame)."""
        self.caps[cap] = self.caps.get(cap, 0) + int(count)
