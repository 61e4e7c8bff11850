"""Frames of asynchronous plots (:mod:`mhtrack.frames`): which trees a frame looks at,
and gating each leaf against each plot at the plot's own time.

*Looked-at trees.* A tree is stepped by a frame when its sensor looked at one of its
leaves (:class:`~mhtrack.mht.coverage.Coverage`, ``P_D > 0``); its leaves then all get a
miss child (``ln(1 − P_D·P_G)``, each leaf with its own ``P_D``: 0 for a leaf the beam
did not or may not have reached, :class:`~mhtrack.mht.coverage.Looks`) and their plot
children, and the window of every leaf of the tree shifts by
one column. The other trees are carried unchanged: no child, no prediction, no score
change, no window shift. N-scan pruning therefore counts a tree's *looks* — the scans
of the target in P1's sense — whatever the number of frames of other sectors and radars
in between (:func:`split_looked`).

*Timed gating* (Blackman & Popoli 1999 §16.2; Stone Soup predicts each track to each
detection's timestamp): the pairs are first found against the leaves predicted to the
frame's time ``t_f`` with a gate that holds every plot time of the frame — the exact gate
``νᵀ S⁻¹ ν ≤ γ`` moved by at most ``d = (|v| + 3σ_v)(t_f − t_min)`` lies inside
``νᵀ (2S + 2d²/γ I)⁻¹ ν ≤ γ`` (Minkowski sum of two ellipses, ``E(A) ⊕ E(B) ⊂ E(2A + 2B)``)
— then each candidate pair is predicted from the leaf's own time to its plot's time and
tested exactly (:func:`gate_timed`).
"""

from __future__ import annotations

import numpy as np

from mhtrack.mht.carry import Carried
from mhtrack.mht.context import FrameContext
from mhtrack.mht.coverage import Looks
from mhtrack.mht.gating import Gate, Gated
from mhtrack.mht.tree import Leaves, contains
from mhtrack.models.linalg2 import gaussian_loglik2, sym_mahalanobis2
from mhtrack.models.motion import MotionModel, States


def looked_trees(tree: np.ndarray, pd: np.ndarray) -> np.ndarray:
    """Mask over leaves (sorted by ``tree``): the leaf's tree has a leaf with ``pd > 0``."""
    return contains(tree[pd > 0], tree)


def split_looked(leaves: Leaves, looks: Looks) -> tuple[Leaves, Looks, Carried | Leaves]:
    """``(looked, their looks, idle)``: the leaves of the trees the frame looked at
    (``P_D > 0`` at one of their leaves) and the others, as rows of ``leaves`` (not
    copied, :class:`~mhtrack.mht.carry.Carried`); the same objects when every tree was
    looked at, with an empty store for the idle leaves."""
    if looks.uniform is not None or (looks.pd > 0).all():  # no tree is carried
        return leaves, looks, _no_leaves(leaves)
    mask = looked_trees(leaves.tree, looks.pd)
    if mask.all():
        return leaves, looks, _no_leaves(leaves)
    rows = mask.nonzero()[0]
    return (leaves.take(rows), Looks(looks.pd.take(rows), looks.certain.take(rows)),
            Carried(leaves, (~mask).nonzero()[0]))


def _no_leaves(leaves: Leaves) -> Leaves:
    """An empty store shaped as ``leaves``."""
    return Leaves.empty(leaves.window.shape[1], leaves.n_models)


def gate_looked(frame: FrameContext, gate: Gate, leaves: Leaves, pred: States, *,
                looks: Looks, motion: MotionModel) -> tuple[Gated, States | None]:
    """Gated pairs of the leaves looked at (``looks.pd > 0``; indices into ``leaves``)
    against the frame's plots and, for timed plots (``t`` not all the frame's time), each
    pair's state predicted to its plot's time."""
    pd = None if looks.uniform is not None else looks.pd
    sub = None if pd is None or (pd > 0).all() else np.flatnonzero(pd > 0)
    lv, pr = (leaves, pred) if sub is None else (leaves.take(sub), pred.take(sub))
    t = frame.t
    if t is None or (t == frame.time).all():
        g, pair_pred = gate(frame, lv, pr, motion), None
    else:
        g, pair_pred = gate_timed(frame, gate, lv, pr, motion=motion)
    if sub is not None:
        g = Gated(sub[g.track], g.plot, g.d2, g.loglik, g.posterior)
    return g, pair_pred


def gate_timed(frame: FrameContext, gate: Gate, leaves: Leaves, pred: States, *,
               motion: MotionModel) -> tuple[Gated, States]:
    """Coarse gate at the frame's time, then the exact gate of each candidate pair at its
    plot's time (module docstring). Returns the pairs (ordered by leaf, then plot) and
    their predicted states."""
    z, R, t, time = frame.z, frame.R, frame.t, frame.time
    assert t is not None
    gamma = gate.gamma
    span = max(time - float(t.min()), 0.0) if t.size else 0.0
    P = pred.P
    speed = np.hypot(pred.x[:, 1], pred.x[:, 3]) + 3.0 * np.sqrt(
        np.maximum(P[:, 1, 1], P[:, 3, 3]))
    extra = 2.0 * (speed * span) ** 2 / gamma
    Pc = 2.0 * P
    Pc[:, 0, 0] += extra
    Pc[:, 2, 2] += extra
    coarse = gate.pairs(frame, leaves, pred.x, Pc, R=2.0 * R, loglik=False)
    ti, pj = coarse.track, coarse.plot
    pp = motion.predict(leaves.states().take(ti), t[pj] - leaves.time[ti])
    Rp = R if R.ndim == 2 else R.take(pj, axis=0)
    d2, det = sym_mahalanobis2(z[:, 0].take(pj) - pp.x[:, 0], z[:, 1].take(pj) - pp.x[:, 2],
                               pp.P[:, 0, 0] + Rp[..., 0, 0], pp.P[:, 0, 2] + Rp[..., 0, 1],
                               pp.P[:, 2, 2] + Rp[..., 1, 1])
    keep = np.flatnonzero(d2 <= gamma)
    pp = pp.take(keep)
    ti, pj, d2, det = ti[keep], pj[keep], d2[keep], det[keep]
    k = np.arange(keep.size)
    loglik, posterior = motion.gating_scores(
        pp, k, pj, z, R, gaussian_loglik2(d2, det) if motion.reads_gate_loglik else None)
    return Gated(ti, pj, d2, loglik, posterior), pp
