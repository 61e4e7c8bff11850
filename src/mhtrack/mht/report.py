"""The report stage: what one scan tells the user — the confirmed tracks of the best
global hypothesis (:func:`report`) and the step's statistics (:class:`StepStats`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from mhtrack.attributes import TrackAttributes
from mhtrack.mht.context import FrameContext
from mhtrack.mht.hypothesis import GlobalHypothesis
from mhtrack.mht.tree import Leaves
from mhtrack.records import Scan, TrackTable


@dataclass(frozen=True)
class StepStats:
    """What one :meth:`~mhtrack.mht.tracker.MHTTracker.step` did.

    ``caps`` maps each hard cap that acted to how many leaves (``max_leaves_per_plot``
    and ``max_tentative_per_plot``, the overload rules of :mod:`mhtrack.mht.caps`;
    ``max_leaves_per_tree``,
    ``max_leaves``), trees (``max_trees``), plots or initiated tracks
    (``max_births_per_scan``) or clusters (``max_cluster_size``) it cut; empty when none
    acted. ``n_births`` counts the trees started at this scan. ``limits``: the caps that
    scale with the scene and their values at this scan (:func:`mhtrack.mht.caps.scaled_limits`).
    """

    scan: int
    n_plots: int
    n_leaves: int
    n_trees: int
    n_clusters: int
    largest_cluster: int
    n_confirmed: int
    time_s: float
    caps: dict[str, int] = field(default_factory=dict)
    n_births: int = 0
    limits: dict[str, int] = field(default_factory=dict)

    @classmethod
    def of(cls, frame: FrameContext, leaves: Leaves, *, births: Leaves,
           hyp: GlobalHypothesis, out: TrackTable, time_s: float) -> StepStats:
        """The statistics of a step: the frame's counters (its plots, the caps that acted
        and its scaled limits), the leaves kept, the new trees, the solve and the
        report."""
        return cls(scan=frame.index, n_plots=frame.n_plots, n_leaves=len(leaves),
                   n_trees=leaves.n_trees, n_clusters=hyp.n_clusters,
                   largest_cluster=hyp.largest_cluster, n_confirmed=len(out), time_s=time_s,
                   caps=frame.caps, n_births=births.n_trees, limits=frame.scaled_limits())


def confirmed_windows(leaves: Leaves, rep: np.ndarray | None = None) -> np.ndarray:
    """Leaf windows (m, N+1) of the confirmed tracks in the best hypothesis: the plots
    they used at scans ``k−N … k`` (``rep``: :meth:`Leaves.reported`, when known)."""
    return leaves.window[leaves.reported() if rep is None else rep]


def report(scan: Scan, leaves: Leaves, stepped: np.ndarray | None = None,
           rep: np.ndarray | None = None, *,
           identity: Callable[[np.ndarray], TrackAttributes] | None = None,
           models: bool = False) -> TrackTable:
    """Confirmed tracks of the best hypothesis at ``scan``, ordered by track id; each row
    at its state's own time (``Leaves.time``). ``stepped`` (mask): only the leaves this
    frame stepped (a frame of one radar's sector reports the tracks it looked at).
    ``rep``: :meth:`Leaves.reported`, when known (not modified). ``identity``: the
    attributes of the reported leaves (their rows, in order) when the plots have them
    (:func:`~mhtrack.mht.track_attributes.track_attributes`). ``models``: each row's
    model states too (``mu, xm, Pm``, for :mod:`mhtrack.models.smoother`)."""
    rep = leaves.reported() if rep is None else rep
    if stepped is not None:
        rep = rep & stepped
    sel = rep.nonzero()[0]
    sel = sel.take(leaves.track.take(sel).argsort(kind="stable"))
    x = leaves.x.take(sel, axis=0)
    n = sel.size
    # ``take``: a copy of the rows, without fancy indexing's set-up
    return TrackTable(
        scan=np.full(n, int(scan.index), np.int64),
        time=leaves.time.take(sel),
        track_id=leaves.track.take(sel),
        x=x[:, 0].copy(),
        y=x[:, 2].copy(),
        vx=x[:, 1].copy(),
        vy=x[:, 3].copy(),
        plot=leaves.window[:, -1].take(sel),
        score=leaves.score.take(sel),
        P=leaves.P.take(sel, axis=0),
        tentative=np.zeros(n, bool),
        attrs=None if identity is None else identity(sel),
        **({"mu": leaves.mu.take(sel, axis=0), "xm": leaves.xm.take(sel, axis=0),
            "Pm": leaves.Pm.take(sel, axis=0)} if models else {}),
    )
