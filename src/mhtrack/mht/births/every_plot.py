"""The ``every-plot`` birth process (P1 Fig. 1): every plot of the scan starts a tree."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from mhtrack.mht.births.base import Birth, BirthCandidates
from mhtrack.mht.context import FrameContext
from mhtrack.mht.scoring import birth_score
from mhtrack.mht.tree import NO_PLOT, one_point_state
from mhtrack.mht.undetected import UndetectedDensity
from mhtrack.models.motion import MotionModel
from mhtrack.records import Scan


class EveryPlotBirth(Birth):
    """Every plot whose birth score ``ln(λ_v P_D / (κ̂ + λ_v))`` is above ``floor`` (the SPRT
    deletion threshold: a tentative tree at or below it would be deleted at once,
    :func:`~mhtrack.mht.sprt.tentative_keep`) starts a tree from its one-point state
    (:func:`~mhtrack.mht.tree.one_point_state`). Over ``max_per_scan`` plots, those outside
    confirmed tracks' gates go first, then those with the highest birth score (then scan
    order).

    Parameters
    ----------
    motion : the tracker's motion model.
    p_detection, new_target_density : ``P_D`` and ``λ_v`` of the birth score.
    floor : the lowest birth score that starts a tree.
    v_max : largest target speed (the one-point velocity variance ``(v_max/2)²``).
    width : columns of the leaf window (``n_scan + 1``).
    max_per_scan : most trees started per scan.
    plot_pd : ``P_D`` of the sensor of a scan's plots (``None``: ``p_detection``), e.g.
        :meth:`mhtrack.mht.coverage.Coverage.plot_pd` for frames of several radars.
    undetected : the start-up density (:class:`~mhtrack.mht.undetected.UndetectedDensity`,
        ``MHTConfig.startup_density``): each frame's ``λ`` is its first-detection density
        (:meth:`scan_density`) instead of ``new_target_density``; ``None``: P1's constant.

    A tree starts at its plot's own time (``Scan.plot_times``).
    """

    def __init__(self, motion: MotionModel, *, p_detection: float, new_target_density: float,
                 floor: float, v_max: float, width: int, max_per_scan: int,
                 plot_pd: Callable[[Scan], float] | None = None,
                 undetected: UndetectedDensity | None = None) -> None:
        super().__init__(motion)
        self.p_detection = p_detection
        self.new_target_density = new_target_density
        self.floor = floor
        self.v_max = v_max
        self.width = width
        self.max_per_scan = max_per_scan
        self.plot_pd = plot_pd
        self.undetected = undetected
        self._density = new_target_density  # this frame's (scan_density)

    def _pd(self, scan: Scan) -> float:
        return self.p_detection if self.plot_pd is None else self.plot_pd(scan)

    def scan_density(self, frame: FrameContext, kappa: np.ndarray) -> float | None:
        if self.undetected is None:
            return None
        self._density = self.undetected.first_detection(frame.z, kappa, self._pd(frame.scan))
        return self._density

    def limit(self, max_per_scan: int) -> None:
        self.max_per_scan = int(max_per_scan)

    def propose(self, frame: FrameContext, kappa: np.ndarray,
                in_gates: np.ndarray | None) -> BirthCandidates:
        scan, z, R, rows = frame.scan, frame.z, frame.R, frame.rows
        density = self.new_target_density if self.undetected is None else self._density
        score = birth_score(kappa, self._pd(scan), density)
        sel = (score > self.floor).nonzero()[0]
        if sel.size > self.max_per_scan:
            gated_first = np.zeros(len(z), bool) if in_gates is None else in_gates
            order = sel[np.lexsort((-score[sel], gated_first[sel]))]
            frame.cut("max_births_per_scan", sel.size - self.max_per_scan)
            sel = np.sort(order[: self.max_per_scan])
        n = sel.size
        x, P = one_point_state(z.take(sel, axis=0), R if R.ndim == 2 else R.take(sel, axis=0),
                               self.v_max)
        window = np.full((n, self.width), NO_PLOT, np.int64)
        window[:, -1] = rows.take(sel)
        start = np.asarray(score.take(sel), float)
        return BirthCandidates(x, P, start, start.copy(), window, np.ones(n, np.int64),
                               scan.plot_times().take(sel))

    def arrays(self) -> dict[str, np.ndarray]:
        return {} if self.undetected is None else self.undetected.arrays()

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        if self.undetected is not None:
            self.undetected.set_arrays(arrays)
