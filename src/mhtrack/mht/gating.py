"""Gating: which leaf–plot pairs are close enough to be a track's update (P1 §1.3).

For a predicted leaf ``(x⁻, P⁻)`` and a plot ``z`` with covariance ``R``::

    ν = z − H x⁻,   S = H P⁻ Hᵀ + R,   d² = νᵀ S⁻¹ ν  ≤  γ
    ln p(z|T) = −½ d² − ½ ln det S − ln 2π        (innovation log-likelihood)

``d²`` is χ² with 2 degrees of freedom, so ``γ = −2 ln(1 − P_G)`` holds a fraction ``P_G``
of true plots (:func:`gate_threshold`). The pairs are found by a sweep over plot strips
(:func:`gate_sweep`) without forming the M × N matrix — or, when M × N is small
(≤ :data:`DENSE_MAX_PAIRS`), on that whole matrix at once, which costs fewer NumPy calls
and gives the same pairs and floats; :class:`Gate` is the tracker's
stage: the frame's work budget ``max_gated_pairs`` and the motion model's likelihood for the score.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from mhtrack.mht.context import FrameContext
from mhtrack.mht.tree import Leaves
from mhtrack.models.linalg2 import gaussian_loglik2, sym_mahalanobis2
from mhtrack.models.motion import MotionModel, States


def gate_threshold(probability: float) -> float:
    """χ² gate ``γ`` with 2 degrees of freedom holding ``probability`` of true plots."""
    if not 0.0 < probability < 1.0:
        raise ValueError(f"gate probability must be in (0, 1), got {probability}")
    # χ² with 2 d.o.f. is exponential with mean 2: P(d² ≤ γ) = 1 − exp(−γ/2), so the
    # quantile is exact in closed form (and needs no scipy.stats at import time).
    return -2.0 * math.log1p(-probability)


@dataclass(frozen=True, slots=True)
class Gated:
    """Track–plot pairs inside the gate: ``track[i]`` with ``plot[i]``, their Mahalanobis
    distance ``d2`` and log-likelihood ``loglik = ln p(z|T)`` (``None`` from a gate asked
    for the pairs only, ``loglik=False``); ``posterior``: per pair
    (rows by ``posterior[rows]``), what the motion model's update may reuse (its
    :meth:`~mhtrack.models.motion.MotionModel.gating_scores`), or ``None``."""

    track: np.ndarray
    plot: np.ndarray
    d2: np.ndarray
    loglik: np.ndarray | None  # None for a model that does not read it (reads_gate_loglik)
    posterior: Any = None

    def __len__(self) -> int:
        return len(self.track)


#: Largest ``M × N`` (tracks × plots) tested as one dense matrix by :func:`gate_sweep`
#: (a few NumPy calls on arrays of this size cost less than the sweep's bookkeeping).
DENSE_MAX_PAIRS = 8192


def plot_covariances(R: np.ndarray, n: int) -> tuple[np.ndarray, bool]:
    """``(R, shared)``: one (2, 2) covariance for all ``n`` plots, or (n, 2, 2)."""
    R = np.asarray(R, float)
    if R.shape == (2, 2):
        return R, True
    if R.shape != (n, 2, 2):
        raise ValueError(f"R must be (2, 2) or ({n}, 2, 2), got {R.shape}")
    return R, False


def _sweep_boxes(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, shared: bool, gamma: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Candidate search of :func:`gate_sweep`: for each (track, strip) query, the range
    ``lo:hi`` of the plots in ``order`` inside the track's gate box. Returns
    ``(tq, lo, hi, order)``."""
    M, N = len(x), len(z)
    # box half-widths with the largest plot covariance (a superset; exact test later)
    rxx = R[0, 0] if shared else R[:, 0, 0].max()
    ryy = R[1, 1] if shared else R[:, 1, 1].max()
    hx = np.sqrt(gamma * (P[:, 0, 0] + rxx)) * (1 + 1e-9) + 1e-9
    hy = np.sqrt(gamma * (P[:, 2, 2] + ryy)) * (1 + 1e-9) + 1e-9
    x0 = float(z[:, 0].min())
    y0 = float(z[:, 1].min())
    height = float(z[:, 1].max()) - y0 + 1.0  # keys of different strips never interleave
    # strip width: the mean box width, but at most ~4·sqrt(N) strips
    width = max(2 * float(hx.mean()), float(np.ptp(z[:, 0])) / (4 * np.sqrt(N) + 1), 1e-6)
    col = np.floor((z[:, 0] - x0) / width).astype(np.int64)
    order = np.lexsort((z[:, 1], col))
    key = col[order] * height + (z[:, 1].take(order) - y0)
    n_cols = int(col.max()) + 1
    c_lo = np.clip(np.floor((x[:, 0] - hx - x0) / width).astype(np.int64), 0, n_cols)
    c_hi = np.clip(np.floor((x[:, 0] + hx - x0) / width).astype(np.int64), -1, n_cols - 1)
    nc = np.maximum(c_hi - c_lo + 1, 0)
    tq = np.repeat(np.arange(M, dtype=np.int64), nc)
    cq = np.repeat(c_lo - np.cumsum(nc) + nc, nc) + np.arange(int(nc.sum()))
    xq, hq = x[:, 2].take(tq), hy.take(tq)
    ylo = np.clip(xq - hq - y0, -0.5, height - 0.5)
    yhi = np.clip(xq + hq - y0, -0.5, height - 0.5)
    lo = np.searchsorted(key, cq * height + ylo, side="left")
    hi = np.searchsorted(key, cq * height + yhi, side="right")
    return tq, lo, hi, order


def gate_candidate_counts(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, gamma: float
) -> np.ndarray:
    """Per track, how many plots :func:`gate_sweep` will test exactly (those in its gate's
    bounding box) — an upper bound on its gated plots, found without forming any pair.
    Lets a caller bound the work of gating before doing it."""
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R, shared = plot_covariances(R, len(z))
    if len(x) == 0 or len(z) == 0:
        return np.zeros(len(x), np.int64)
    tq, lo, hi, _ = _sweep_boxes(x, P, z, R, shared, gamma)
    return np.bincount(tq, weights=hi - lo, minlength=len(x)).astype(np.int64)


def gate_sweep(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, gamma: float,
    loglik: bool = True,
) -> Gated:
    """Every track–plot pair with ``d² ≤ γ`` and its innovation log-likelihood, ordered by
    track then plot; ``x`` (M, 4), ``P`` (M, 4, 4) predicted, ``z`` (N, 2), ``R`` (2, 2)
    or (N, 2, 2).

    The gate ellipse ``νᵀ S⁻¹ ν ≤ γ`` lies inside the box ``|νx| ≤ √(γ S_xx)``,
    ``|νy| ≤ √(γ S_yy)``. Plots are bucketed into vertical strips and sorted by ``y``
    within each; every track looks up, in each strip its box overlaps, the plots in its
    ``y`` range with one vectorised ``searchsorted``. Work and memory are
    O(M·strips-per-box + pairs in boxes), whatever M × N is. ``loglik=False``: the
    pairs and ``d2`` only (``loglik`` ``None``).
    """
    x = np.asarray(x, float).reshape(-1, 4)
    z = np.asarray(z, float).reshape(-1, 2)
    R, shared = plot_covariances(R, len(z))
    if len(x) == 0 or len(z) == 0:
        e = np.zeros(0, np.int64)
        return Gated(e, e, np.zeros(0), np.zeros(0) if loglik else None)
    if len(x) * len(z) <= DENSE_MAX_PAIRS:
        return _dense_pairs(x, P, z, R, shared, gamma, loglik)
    return _pairs_in_boxes(x, P, z, R, shared, gamma, _sweep_boxes(x, P, z, R, shared, gamma),
                           loglik)


def _dense_pairs(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, shared: bool, gamma: float,
    loglik: bool = True,
) -> Gated:
    """The exact test of :func:`gate_sweep` on every (track, plot) pair as an (M, N)
    matrix: the same elementwise operations on the same operands as
    :func:`_pairs_in_boxes` (so the same floats), pairs in row-major order — by track,
    then plot."""
    Rb = R if shared else R.transpose(1, 2, 0)  # (2, 2) or (2, 2, N)
    s00 = P[:, 0, 0][:, None] + Rb[0, 0]
    s01 = P[:, 0, 2][:, None] + Rb[0, 1]
    s11 = P[:, 2, 2][:, None] + Rb[1, 1]
    n0 = z[:, 0] - x[:, 0][:, None]
    n1 = z[:, 1] - x[:, 2][:, None]
    d2, det = sym_mahalanobis2(n0, n1, s00, s01, s11)
    flat = (d2 <= gamma).ravel().nonzero()[0]  # row-major: by track, then plot
    ti = flat // len(z)
    pj = flat - ti * len(z)
    d2 = d2.ravel().take(flat)
    if not loglik:
        return Gated(ti, pj, d2, None)
    det = det.ravel().take(ti if shared else flat)  # (M, 1) when R is shared
    return Gated(ti, pj, d2, gaussian_loglik2(d2, det))


def _pairs_in_boxes(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, shared: bool, gamma: float,
    boxes: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], loglik: bool = True,
) -> Gated:
    """The exact test of :func:`gate_sweep` on the candidates of :func:`_sweep_boxes`
    (any boxes holding every gated pair give the same result: the test is per pair and
    the pairs are sorted at the end)."""
    N = len(z)
    e = np.zeros(0, np.int64)
    tq, lo, hi, order = boxes
    cnt = hi - lo
    ti = np.repeat(tq, cnt)
    pj = order[np.repeat(lo - np.cumsum(cnt) + cnt, cnt) + np.arange(int(cnt.sum()))]
    if ti.size == 0:
        return Gated(e, e, np.zeros(0), np.zeros(0) if loglik else None)
    if shared:
        s00 = P[:, 0, 0].take(ti) + R[0, 0]
        s01 = P[:, 0, 2].take(ti) + R[0, 1]
        s11 = P[:, 2, 2].take(ti) + R[1, 1]
    else:
        s00 = P[:, 0, 0].take(ti) + R[:, 0, 0].take(pj)
        s01 = P[:, 0, 2].take(ti) + R[:, 0, 1].take(pj)
        s11 = P[:, 2, 2].take(ti) + R[:, 1, 1].take(pj)
    n0 = z[:, 0].take(pj) - x[:, 0].take(ti)
    n1 = z[:, 1].take(pj) - x[:, 2].take(ti)
    d2, det = sym_mahalanobis2(n0, n1, s00, s01, s11)
    # the pairs in the gate, sorted by track then plot: one take of each column (the
    # candidates are grouped by track already; timsort on the nearly sorted key is ~linear)
    keep = (d2 <= gamma).nonzero()[0]
    o = keep.take(np.argsort(ti.take(keep) * N + pj.take(keep), kind="stable"))
    ti, pj, d2 = ti.take(o), pj.take(o), d2.take(o)
    return Gated(ti, pj, d2, gaussian_loglik2(d2, det.take(o)) if loglik else None)


class Gate:
    """The gating stage: every predicted leaf against every plot of a frame, with bounded
    work.

    When the leaves' gate boxes hold more than the frame's ``max_gated_pairs`` candidate
    pairs (a clutter burst), leaves of confirmed trees and then the best-scoring leaves
    are gated first until the budget is spent; the others only get a miss child this scan
    (counted as ``max_gated_pairs`` in the frame's caps). The pairs' ``loglik`` is the
    motion model's (:meth:`~mhtrack.models.motion.MotionModel.gating_scores`: the IMM's
    mixture; the single Gaussian's of ``x, P`` is computed only for a model that reads
    it, :attr:`~mhtrack.models.motion.MotionModel.reads_gate_loglik`).
    """

    def __init__(self, probability: float) -> None:
        self.gamma = gate_threshold(probability)

    def __call__(self, frame: FrameContext, leaves: Leaves, pred: States,
                 motion: MotionModel) -> Gated:
        g = self.pairs(frame, leaves, pred.x, pred.P, loglik=motion.reads_gate_loglik)
        return Gated(g.track, g.plot, g.d2, *motion.gating_scores(
            pred, g.track, g.plot, frame.z, frame.R, g.loglik))

    def pairs(self, frame: FrameContext, leaves: Leaves, xp: np.ndarray, Pp: np.ndarray, *,
              R: np.ndarray | None = None, loglik: bool = True) -> Gated:
        """The pairs of :func:`gate_sweep` of states ``xp``, ``Pp`` against the frame's
        plots (with covariances ``R``; ``None``: the frame's) within the work budget
        (class docstring), with the Gaussian ``loglik`` of ``xp, Pp`` (``loglik=False``:
        ``None``)."""
        z, R = frame.z, frame.R if R is None else R
        budget = frame.limits.max_gated_pairs
        if len(leaves) * len(z) <= budget or len(leaves) == 0 or len(z) == 0:
            return gate_sweep(xp, Pp, z, R, self.gamma, loglik)
        # the candidate boxes are found once: counted against the budget, then tested
        R, shared = plot_covariances(R, len(z))
        boxes = _sweep_boxes(xp, Pp, z, R, shared, self.gamma)
        tq, lo, hi, plot_order = boxes
        counts = np.bincount(tq, weights=hi - lo, minlength=len(leaves)).astype(np.int64)
        if counts.sum() <= budget:
            return _pairs_in_boxes(xp, Pp, z, R, shared, self.gamma, boxes, loglik)
        order = np.lexsort((-leaves.score, leaves.track < 0))
        sel = np.sort(order[np.cumsum(counts[order]) <= budget])
        frame.cut("max_gated_pairs", len(leaves) - sel.size)
        new_index = np.full(len(leaves), -1, np.int64)
        new_index[sel] = np.arange(sel.size)
        q = new_index[tq] >= 0
        g = _pairs_in_boxes(xp[sel], Pp[sel], z, R, shared, self.gamma,
                            (new_index[tq[q]], lo[q], hi[q], plot_order), loglik)
        return Gated(sel[g.track], g.plot, g.d2, g.loglik)


def plots_in_confirmed_gates(leaves: Leaves, gated: Gated, n_plots: int) -> np.ndarray | None:
    """Mask of plots inside the gate of a confirmed track reported at the last scan, or
    ``None`` when there is none (the clutter estimator's ``in_track_gates``)."""
    reported = leaves.reported()
    if not reported.any():
        return None
    mask = np.zeros(n_plots, bool)
    mask[gated.plot[reported[gated.track]]] = True
    return mask
