"""Extend the track trees (P1 §1.3, Fig. 1; eqs. 4–5): every leaf proposes a miss child and
one child per plot in its gate, scored by the log-likelihood ratio increments; the
children that survive pruning are then grown into leaves by the motion model's update.

Proposing is cheap (indices and scores only), so SPRT deletion and the caps act on the
:class:`Children` before the costly Kalman update of :func:`grow_children`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mhtrack.mht.context import FrameContext
from mhtrack.mht.gating import Gated
from mhtrack.mht.tree import NO_PLOT, Leaves
from mhtrack.models.motion import MotionModel, States, row_index

#: Updated children per block of :func:`grow_children`.
UPDATE_BLOCK = 1024


@dataclass(frozen=True, slots=True)
class Children:
    """Candidate children of the leaves before their Kalman update (cheap to prune).

    ``parent`` indexes the parent leaf, ``plot`` the plot within the scan (``-1``: miss),
    ``pair`` the gated pair (``-1``: miss); rows are ordered by parent, the miss first,
    then plots in scan order.
    """

    parent: np.ndarray
    plot: np.ndarray
    score: np.ndarray
    peak: np.ndarray
    pair: np.ndarray

    def __len__(self) -> int:
        return int(self.parent.shape[0])

    def take(self, idx: np.ndarray) -> Children:
        idx = row_index(idx)
        return Children(self.parent.take(idx), self.plot.take(idx), self.score.take(idx),
                        self.peak.take(idx), self.pair.take(idx))


def propose_children(
    leaves: Leaves, gated: Gated, miss_dl: float | np.ndarray, update_dl: np.ndarray
) -> Children:
    """Each leaf spawns a miss child (``L + ΔL_miss``) and one child per gated plot
    (``L + ΔL_update``), P1 eqs. 4–5. ``update_dl`` is per gated pair, ``miss_dl`` one
    value or one per leaf (its sensor coverage's ``P_D``)."""
    n = len(leaves)
    parent = np.concatenate((np.arange(n, dtype=np.int64), gated.track))
    plot = np.concatenate((np.full(n, NO_PLOT, np.int64), gated.plot))
    pair = np.concatenate((np.full(n, -1, np.int64), np.arange(len(gated), dtype=np.int64)))
    score = np.concatenate((leaves.score + miss_dl, leaves.score[gated.track] + update_dl))
    # gated pairs are sorted by (leaf, plot); a stable sort on the parent puts the miss
    # first and keeps the plot order.
    order = np.argsort(parent, kind="stable")
    parent, plot, score, pair = parent[order], plot[order], score[order], pair[order]
    return Children(parent, plot, score, np.maximum(leaves.peak[parent], score), pair)


def grow_children(frame: FrameContext, leaves: Leaves, pred: States, children: Children, *,
                  motion: MotionModel, pair_pred: States | None = None,
                  posterior: Any = None) -> Leaves:
    """Materialise ``children`` as leaves: misses keep the prediction ``pred`` (at the
    frame's time), updates get the motion model's update with their plot of the frame
    (``frame.R`` shared (2, 2) or per plot (n, 2, 2); with an IMM, each model's update and
    ``x, P`` their mixture). With asynchronous plots the update starts from
    ``pair_pred``, the parent predicted to its plot's own time (one row per gated pair),
    and the child's time is the plot's (``frame.t``, when the frame has plot times).
    ``posterior``: per gated pair, what the gate computed for the update
    (:attr:`~mhtrack.mht.gating.Gated.posterior`)."""
    z, R, rows, time = frame.z, frame.R, frame.rows, frame.time
    plot_time = frame.t
    par, plot = children.parent, children.plot
    child_time = np.full(len(par), float(time), float)
    is_upd = plot >= 0
    upd = is_upd.nonzero()[0]
    st = None if pair_pred is not None else motion.children_states(
        pred, par, plot, children.pair, z, R, posterior)
    if st is None:
        st = _grow_states(pred, children, upd, z, R, motion, pair_pred, posterior)
    if upd.size and plot_time is not None:
        child_time[upd] = plot_time[plot[upd]]
    new_col = np.full(len(par), NO_PLOT, np.int64)
    new_col[upd] = rows.take(plot.take(upd))  # the plot's row id; a miss: NO_PLOT
    window = np.concatenate((leaves.window.take(par, axis=0)[:, 1:], new_col[:, None]),
                            axis=1)
    return Leaves(
        x=st.x,
        P=st.P,
        score=children.score,
        peak=children.peak,
        tree=leaves.tree[par],
        track=leaves.track[par],
        birth=leaves.birth[par],
        n_updates=leaves.n_updates[par] + is_upd,
        window=window,
        chosen=np.zeros(len(par), bool),
        mu=st.mu,
        xm=st.xm,
        Pm=st.Pm,
        node=np.full(len(par), -1, np.int64),
        parent=leaves.node[par],
        time=child_time,
        level=leaves.level.take(par, axis=0),
        ident=leaves.ident.take(par, axis=0),
    )


def _grow_states(pred: States, children: Children, upd: np.ndarray, z: np.ndarray,
                 R: np.ndarray, motion: MotionModel, pair_pred: States | None,
                 posterior: Any) -> States:
    """The children's states (:func:`grow_children`): the parents' predictions, the
    updates' rows replaced by the motion model's update, block by block of rows (a block's
    copies stay in the CPU cache; the update is row by row: the floats of one pass)."""
    par, plot = children.parent, children.plot
    st = pred.take(par)
    for s in range(0, upd.size, UPDATE_BLOCK):
        u = upd[s:s + UPDATE_BLOCK]
        pj = plot[u]
        pairs = children.pair[u]
        start = pred.take(par[u]) if pair_pred is None else pair_pred.take(pairs)
        zu, Ru = z.take(pj, axis=0), R if R.ndim == 2 else R.take(pj, axis=0)
        # posterior only when the model's gating_scores gave one: a model written against
        # update(states, z, R) keeps working
        st.put(u, motion.update(start, zu, Ru) if posterior is None
               else motion.update(start, zu, Ru, posterior=posterior[pairs]))
    return st
