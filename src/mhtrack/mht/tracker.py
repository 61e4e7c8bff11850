"""The track-oriented MHT (P1 §1.3, Fig. 1): one call of :meth:`MHTTracker.step` per scan.

The tracking cycle, each step one function::

    predict          kalman.predict_cv              all leaves to the scan time
    gate and score   kalman.gate_sweep              every leaf against every plot
    clutter          clutter.update / intensity     κ̂(z) of the scan's plots
    extend trees     tree.propose_children          miss + one child per gated plot
                     pruning.sprt_keep, ...         delete/prune children (cheap, before
                     tree.grow_children               their Kalman update)
                     tree.birth_leaves              every plot starts a tree, or
                     birth.InitiatorBirth             a P2 initiator over the last 4 scans
    global hyp.      hypothesis.best_hypothesis     clusters → best compatible leaves
    N-scan pruning   pruning.n_scan_keep            decide scan k − N
    caps             pruning.cap_trees
    confirm          SPRT on the chosen leaves      stable track ids
    report           TrackTable of confirmed tracks in the best hypothesis
    clutter          clutter.forget (if it has one)   the confirmed tracks' plots leave
                                                    the estimator's window
    backfill         history.TentativeHistory       the tentative past of tracks
                                                    confirmed at this scan
"""

from __future__ import annotations

import json
import logging
import time
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from os import PathLike
from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.known import KnownClutter
from mhtrack.mht.birth import EVERY_PLOT, BirthCandidates, InitiatorBirth
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.history import TentativeHistory
from mhtrack.mht.hypothesis import best_hypothesis
from mhtrack.mht.pruning import (
    cap_leaves,
    cap_leaves_per_tree,
    cap_trees,
    n_scan_keep,
    score_drop_keep,
    sprt_keep,
    tentative_keep,
)
from mhtrack.mht.scoring import birth_score, miss_increment, sprt_thresholds, update_increment
from mhtrack.mht.tree import (
    Children,
    Leaves,
    birth_leaves,
    grow_children,
    model_arrays,
    propose_children,
    root_links,
)
from mhtrack.models import imm, kalman
from mhtrack.models.motion import ConstantVelocity
from mhtrack.records import MAX_COORDINATE, PlotTable, Scan, TrackTable

logger = logging.getLogger(__name__)

FORMAT = "mhtrack.mht.MHTTracker/3"


@dataclass(frozen=True)
class StepStats:
    """What one :meth:`MHTTracker.step` did.

    ``caps`` maps each hard cap that acted to how many leaves (``max_leaves_per_tree``,
    ``max_leaves``), trees (``max_trees``), plots or initiated tracks
    (``max_births_per_scan``) or clusters (``max_cluster_size``) it cut; empty when none
    acted. ``n_births`` counts the trees started at this scan.
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


class MHTTracker:
    """Track-oriented multiple hypothesis tracker with a pluggable clutter estimator.

    Parameters
    ----------
    config : tracker parameters (:class:`MHTConfig`; defaults from P1 §3).
    clutter : the clutter estimator giving ``κ̂(z)``; default a known constant
        ``κ = 1e−9`` per m² (P1's plain MHT).

    Examples
    --------
    >>> trk = MHTTracker(MHTConfig(), KnownClutter(6.25e-7))
    >>> tracks = trk.run(plot_table)          # doctest: +SKIP
    >>> out = trk.step(scan); trk.last_stats  # doctest: +SKIP
    """

    def __init__(
        self, config: MHTConfig | None = None, clutter: ClutterEstimator | None = None
    ) -> None:
        self.config = MHTConfig() if config is None else config
        self.clutter: ClutterEstimator = KnownClutter() if clutter is None else clutter
        cfg = self.config
        self._motion = ConstantVelocity(cfg.sigma_v)
        self._R = np.eye(2) * cfg.sigma_w**2
        self._gamma = kalman.gate_threshold(cfg.gate_probability)
        self._miss_dl = miss_increment(
            cfg.p_detection, cfg.gate_probability if cfg.miss_uses_gate_probability else None
        )
        self.confirm_threshold, self.delete_threshold = sprt_thresholds(cfg.alpha, cfg.beta)
        self._models = cfg.models
        self._leaves = Leaves.empty(cfg.n_scan + 1, 0 if self._models is None else self._models.r)
        self._last_time: float | None = None
        self._last_index: int | None = None
        self._next_tree = 0
        self._next_track = 0
        self._next_node = 0
        self._history = TentativeHistory(cfg.history_scans)
        self.last_stats: StepStats | None = None
        #: Rows, at earlier scans, of the tracks confirmed by the last :meth:`step`: their
        #: tentative past (``tentative`` true; :mod:`mhtrack.mht.history`).
        self.last_backfill: TrackTable = TrackTable.empty()
        self._caps_warned: set[str] = set()
        self._birth: InitiatorBirth | None = None
        if cfg.birth != EVERY_PLOT:
            self._birth = InitiatorBirth(
                cfg.birth, theta_deg=cfg.birth_theta_deg, width=cfg.n_scan + 1,
                p_detection=cfg.p_detection, new_target_density=cfg.new_target_density,
                miss_dl=self._miss_dl, v_max=cfg.v_max, sigma_v=cfg.sigma_v,
                floor=self.delete_threshold, models=self._models)

    # ------------------------------------------------------------------ public API
    @property
    def leaves(self) -> Leaves:
        """The current hypothesis store (read-only view for inspection and tests)."""
        return self._leaves

    @property
    def birth_process(self) -> InitiatorBirth | None:
        """The initiator birth process and its window, ``None`` for ``every-plot``."""
        return self._birth

    def step(self, scan: Scan) -> TrackTable:
        """Process one scan; return the confirmed tracks of the best global hypothesis.

        Statistics of the step are left in :attr:`last_stats`, the earlier rows of tracks
        confirmed at this scan in :attr:`last_backfill`; a warning is logged (once) when a
        hard cap acted.
        """
        t0 = time.perf_counter()
        cfg = self.config
        z, R, rows = self._validate(scan)
        caps: dict[str, int] = {}
        leaves = self._leaves
        previous = _Reported.of(leaves)

        xp, Pp, model_pred = self._predict(leaves, scan)
        gated = self._gate(leaves, xp, Pp, z, R, caps)
        if model_pred is not None and len(gated):
            # IMM: the score uses the mixture likelihood Σ_j μ̄_j N(z; H x⁻_j, S_j)
            g, pj = gated.track, gated.plot
            ll = imm.model_logliks(model_pred[0][g], model_pred[1][g], z[pj],
                                   R if R.ndim == 2 else R[pj])
            gated = kalman.Gated(g, pj, gated.d2, imm.mixture_loglik(model_pred[2][g], ll))
        in_gates = _plots_in_confirmed_gates(leaves, gated, len(z))
        kappa = self._clutter_intensity(scan, z, in_gates)

        update_dl = update_increment(
            gated.loglik, kappa[gated.plot], cfg.p_detection, cfg.new_target_density
        )
        children = propose_children(leaves, gated, self._miss_dl, update_dl)
        if self._birth is None:
            births = self._births(scan, z, R, rows, kappa, in_gates, caps)
            n_births = len(births)
        else:
            cand = self._initiated(scan, z, R, rows, kappa, caps)
            n_births = len(cand)
        children = self._prune_children(leaves, children, n_births, caps)
        grown = grow_children(leaves, xp, Pp, children, z, R, rows, model_pred)
        if self._birth is not None:
            births = self._seed(scan, *self._birth.select(cand, grown.window), caps)
        leaves = Leaves.concat(grown, births)
        leaves = replace(leaves, node=np.arange(self._next_node, self._next_node + len(leaves),
                                                dtype=np.int64))
        self._next_node += len(leaves)

        hyp = best_hypothesis(
            leaves.score, leaves.tree, leaves.window, cfg.max_cluster_size, cfg.milp_time_limit
        )
        if hyp.n_greedy:
            caps["max_cluster_size"] = hyp.n_greedy
        if hyp.n_time_limited:
            caps["milp_time_limit"] = hyp.n_time_limited
        leaves = self._prune_after_solve(leaves, hyp.leaves, caps)
        first_new = self._next_track
        leaves = self._manage_tracks(leaves, previous)
        self.last_backfill = self._history.backfill(
            leaves, np.flatnonzero(leaves.chosen & (leaves.track >= first_new)))
        self._history.record(int(scan.index), float(scan.time), leaves)
        confirmed = leaves.chosen & (leaves.track >= 0)
        if self._birth is not None:
            self._birth.forget_used(leaves.window[confirmed])
        forget = getattr(self.clutter, "forget", None)
        if forget is not None and len(z):
            forget(np.isin(rows, leaves.window[confirmed, -1]))
        self._leaves = leaves
        self._last_time, self._last_index = float(scan.time), int(scan.index)

        out = self._report(scan, leaves)
        self.last_stats = StepStats(
            scan=int(scan.index),
            n_plots=len(z),
            n_leaves=len(leaves),
            n_trees=leaves.n_trees,
            n_clusters=hyp.n_clusters,
            largest_cluster=hyp.largest_cluster,
            n_confirmed=len(out),
            time_s=time.perf_counter() - t0,
            caps=caps,
            n_births=int(np.unique(births.tree).size),
        )
        if caps:
            new = sorted(set(caps) - self._caps_warned)
            if new:  # a warning the first time each cap acts; every scan's counts at DEBUG
                self._caps_warned.update(new)
                logger.warning(
                    "MHT scan %d: hard caps acted: %s (first time for %s; per-scan counts are "
                    "in StepStats.caps)", scan.index, caps, ", ".join(new))
            else:
                logger.debug("MHT scan %d: hard caps acted: %s", scan.index, caps)
        return out

    def run(
        self, scans: Iterable[Scan] | PlotTable, stats: list[StepStats] | None = None,
        *, history: bool = True,
    ) -> TrackTable:
        """Step through ``scans`` (or all scans of a :class:`PlotTable`) and concatenate the
        outputs, ordered by scan then track id; per-scan statistics are appended to
        ``stats`` when given. With ``history`` (default) the output also holds each
        track's tentative past (:attr:`last_backfill` of every step, ``tentative`` true);
        without, only what each step reported at its own scan."""
        if isinstance(scans, PlotTable):
            scans = scans.scans()
        parts = []
        for scan in scans:
            parts.append(self.step(scan))
            if history:
                parts.append(self.last_backfill)
            if stats is not None and self.last_stats is not None:
                stats.append(self.last_stats)
        out = TrackTable.concat(parts)
        return out.sorted() if history else out

    # ------------------------------------------------------------------ cycle steps
    def _validate(self, scan: Scan) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Check the scan at the library boundary; return ``z``, ``R`` and row ids."""
        z = np.asarray(scan.z, dtype=float).reshape(-1, 2)
        n = len(z)
        rows = np.asarray(scan.rows, dtype=np.int64).reshape(-1)
        if rows.size != n:
            raise ValueError(f"scan {scan.index}: {rows.size} row ids for {n} plots")
        if not np.isfinite(scan.time):
            raise ValueError(f"scan {scan.index}: time {scan.time} is not finite")
        if self._last_time is not None and not scan.time > self._last_time:
            raise ValueError(
                f"scan {scan.index}: time {scan.time} s is not after the previous scan "
                f"({self._last_index}, {self._last_time} s); dt must be > 0"
            )
        bad = ~np.isfinite(z).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"scan {scan.index}: plot row {int(rows[i])} has a non-finite position "
                f"{z[i].tolist()}"
            )
        far = np.abs(z).max(axis=1) > MAX_COORDINATE if n else np.zeros(0, bool)
        if far.any():
            i = int(np.flatnonzero(far)[0])
            raise ValueError(
                f"scan {scan.index}: plot row {int(rows[i])} lies at {z[i].tolist()} m, "
                f"beyond ±{MAX_COORDINATE:g} m of the frame's origin (a unit or parsing "
                "error?)"
            )
        if n > 1 and np.unique(rows).size != n:
            raise ValueError(f"scan {scan.index}: plot row ids are not unique")
        if scan.R is None:
            return z, self._R, rows
        R = np.asarray(scan.R, dtype=float)
        if R.shape != (n, 2, 2):
            raise ValueError(f"scan {scan.index}: R has shape {R.shape}, expected ({n}, 2, 2)")
        unset = np.isnan(R).all(axis=(1, 2))  # PlotTable.from_scans: "use the tracker's R"
        if unset.any():
            R = R.copy()
            R[unset] = self._R
        det = R[:, 0, 0] * R[:, 1, 1] - R[:, 0, 1] * R[:, 1, 0]
        bad = ~(np.isfinite(R).all(axis=(1, 2)) & (R[:, 0, 0] > 0) & (det > 0))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"scan {scan.index}: plot row {int(rows[i])} has an invalid covariance "
                f"{R[i].tolist()}"
            )
        return z, R, rows

    def _predict(
        self, leaves: Leaves, scan: Scan
    ) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray] | None]:
        """All leaves to the scan time, ``dt`` = time since last scan: ``(x⁻, P⁻, models)``
        with the CV model (``models`` None), or with the IMM (``models = (x⁻_j, P⁻_j, μ̄)``
        per model and ``x⁻, P⁻`` their mixture, used for gating)."""
        if len(leaves) == 0 or self._last_time is None:
            models = None if self._models is None else (leaves.xm, leaves.Pm, leaves.mu)
            return leaves.x, leaves.P, models
        dt = float(scan.time) - self._last_time
        if self._models is None:
            xp, Pp = kalman.predict_cv(leaves.x, leaves.P, dt, self._motion.Q(dt))
            return xp, Pp, None
        xm, Pm, mubar = self._models.predict(leaves.xm, leaves.Pm, leaves.mu, dt)
        xp, Pp = imm.combine(xm, Pm, mubar)
        return xp, Pp, (xm, Pm, mubar)

    def _gate(
        self,
        leaves: Leaves,
        xp: np.ndarray,
        Pp: np.ndarray,
        z: np.ndarray,
        R: np.ndarray,
        caps: dict[str, int],
    ) -> kalman.Gated:
        """Gate every predicted leaf against every plot (χ², 2 d.o.f.).

        Bounded work: when the leaves' gate boxes hold more than ``max_gated_pairs``
        candidate pairs (a clutter burst), leaves of confirmed trees and then the
        best-scoring leaves are gated first until the budget is spent; the others only
        get a miss child this scan."""
        budget = self.config.max_gated_pairs
        if len(leaves) * len(z) <= budget:
            return kalman.gate_sweep(xp, Pp, z, R, self._gamma)
        counts = kalman.gate_candidate_counts(xp, Pp, z, R, self._gamma)
        if counts.sum() <= budget:
            return kalman.gate_sweep(xp, Pp, z, R, self._gamma)
        order = np.lexsort((-leaves.score, leaves.track < 0))
        sel = np.sort(order[np.cumsum(counts[order]) <= budget])
        caps["max_gated_pairs"] = len(leaves) - sel.size
        g = kalman.gate_sweep(xp[sel], Pp[sel], z, R, self._gamma)
        return kalman.Gated(sel[g.track], g.plot, g.d2, g.loglik)

    def _clutter_intensity(
        self, scan: Scan, z: np.ndarray, in_gates: np.ndarray | None
    ) -> np.ndarray:
        """Feed the estimator, then ``κ̂(z)`` of every plot (floored, see MHTConfig)."""
        self.clutter.update(scan, in_gates)
        kappa = np.asarray(self.clutter.intensity(z), dtype=float).reshape(-1)
        if kappa.shape != (len(z),) or not np.isfinite(kappa).all() or (kappa < 0).any():
            raise ValueError(
                f"scan {scan.index}: clutter estimator {self.clutter.name!r} returned an "
                f"invalid intensity (need {len(z)} finite values >= 0)"
            )
        return np.maximum(kappa, self.config.min_clutter_density)

    def _births(
        self,
        scan: Scan,
        z: np.ndarray,
        R: np.ndarray,
        rows: np.ndarray,
        kappa: np.ndarray,
        in_gates: np.ndarray | None,
        caps: dict[str, int],
    ) -> Leaves:
        """Every plot whose birth score ``ln(λ_v P_D / (κ̂ + λ_v))`` is above the SPRT deletion
        threshold starts a tree (a tentative tree at or below it would be deleted at
        once, :func:`~mhtrack.mht.pruning.tentative_keep`). Over ``max_births_per_scan``
        plots, those outside confirmed tracks' gates go first, then those with the highest
        birth score (then scan order)."""
        cfg = self.config
        score = birth_score(kappa, cfg.p_detection, cfg.new_target_density)
        sel = np.flatnonzero(score > self.delete_threshold)
        if sel.size > cfg.max_births_per_scan:
            gated_first = np.zeros(len(z), bool) if in_gates is None else in_gates
            order = sel[np.lexsort((-score[sel], gated_first[sel]))]
            caps["max_births_per_scan"] = sel.size - cfg.max_births_per_scan
            sel = np.sort(order[: cfg.max_births_per_scan])
        Rb = R if R.ndim == 2 else R[sel]
        out = birth_leaves(z[sel], Rb, rows[sel], score[sel], self._next_tree, int(scan.index),
                           cfg.v_max, cfg.n_scan + 1, self._models)
        self._next_tree += sel.size
        return out

    def _initiated(
        self,
        scan: Scan,
        z: np.ndarray,
        R: np.ndarray,
        rows: np.ndarray,
        kappa: np.ndarray,
        caps: dict[str, int],
    ) -> BirthCandidates:
        """Initiator birth process: the tracks initiated over the last scans with a plot
        at this one (``mhtrack.mht.birth``); over ``max_births_per_scan``, the highest
        birth scores (then initiator order)."""
        assert self._birth is not None
        cand = self._birth.propose(scan, z, R, rows, kappa)
        cap = self.config.max_births_per_scan
        if len(cand) > cap:
            caps["max_births_per_scan"] = len(cand) - cap
            cand = cand.take(np.sort(np.argsort(-cand.score, kind="stable")[:cap]))
        return cand

    def _seed(self, scan: Scan, cand: BirthCandidates, group: np.ndarray,
              caps: dict[str, int]) -> Leaves:
        """New trees from initiated tracks: one tree per plot of this scan that ends
        initiated tracks, its leaves those tracks (state, covariance, score, plots), pruned
        as children are (score drop within the tree, leaves per tree)."""
        cfg = self.config
        keep = score_drop_keep(group, cand.score, cfg.prune_drop)
        cand, group = cand.take(keep), group[keep]
        keep, cut = cap_leaves_per_tree(group, cand.score, cfg.max_leaves_per_tree)
        if cut:
            caps["max_leaves_per_tree"] = caps.get("max_leaves_per_tree", 0) + cut
            cand, group = cand.take(keep), group[keep]
        n = len(cand)
        first = self._next_tree
        self._next_tree += int(group.max()) + 1 if n else 0
        return Leaves(
            x=cand.x,
            P=cand.P,
            score=cand.score,
            peak=cand.peak,
            tree=first + group,
            track=np.full(n, -1, np.int64),
            birth=np.full(n, int(scan.index), np.int64),
            n_updates=cand.n_updates,
            window=cand.window,
            chosen=np.zeros(n, bool),
            **model_arrays(cand.x, cand.P, self._models),
            **root_links(n),
        )

    def _prune_children(
        self, leaves: Leaves, children: Children, n_births: int, caps: dict[str, int]
    ) -> Children:
        """Before the (costly) Kalman update: SPRT deletion, score-drop pruning within a
        tree, then the caps on leaves per tree and on all leaves."""
        cfg = self.config
        keep = sprt_keep(children.score, children.peak, self.delete_threshold)
        keep &= tentative_keep(children.score, leaves.track[children.parent] < 0,
                               self.delete_threshold)
        children = children.take(keep)
        tree = leaves.tree[children.parent]
        keep = score_drop_keep(tree, children.score, cfg.prune_drop)
        children, tree = children.take(keep), tree[keep]
        keep, cut = cap_leaves_per_tree(tree, children.score, cfg.max_leaves_per_tree)
        if cut:
            caps["max_leaves_per_tree"] = cut
            children, tree = children.take(keep), tree[keep]
        budget = max(cfg.max_leaves - n_births, 0)
        confirmed = leaves.track[children.parent] >= 0
        keep, cut = cap_leaves(children.score, confirmed, budget)
        if cut:
            caps["max_leaves"] = cut
            children = children.take(keep)
        return children

    def _prune_after_solve(
        self, leaves: Leaves, chosen: np.ndarray, caps: dict[str, int]
    ) -> Leaves:
        """N-scan pruning around the best hypothesis, then the cap on trees; marks the
        surviving chosen leaves."""
        is_chosen = np.zeros(len(leaves), bool)
        is_chosen[chosen] = True
        keep = n_scan_keep(leaves.tree, leaves.window[:, 0], chosen)
        protected = is_chosen | (leaves.track >= 0)
        keep_t, cut = cap_trees(leaves.tree[keep], leaves.score[keep], protected[keep],
                                self.config.max_trees)
        if cut:
            caps["max_trees"] = cut
            keep[np.flatnonzero(keep)[~keep_t]] = False
        out = leaves.take(keep)
        return replace(out, chosen=is_chosen[keep])

    def _manage_tracks(self, leaves: Leaves, previous: _Reported) -> Leaves:
        """Track identity and SPRT confirmation on the chosen leaves.

        1. *Hand-over*: a tentative tree whose chosen leaf shares a plot (within the
           window) with a track reported at the previous scan that the best hypothesis no
           longer carries takes over that track's id — the track follows its plots, not
           its tree (most shared plots first, then lower tree and track id).
        2. *Confirmation*: a tentative tree whose chosen leaf has ``L ≥ ln((1−β)/α)``
           (SPRT; Wald 1947; Blackman & Popoli 1999 §6.2), or has used plots in at least
           ``confirm_hits`` of the ``N + 1`` scans of its window with
           ``L > confirm_min_score`` (M-of-N logic), and whose branch holds at least
           ``confirm_min_plots`` plots, gets the next track id, in tree-id order; ids are
           never reused.
        """
        track = leaves.track
        chosen = np.flatnonzero(leaves.chosen)
        carried = track[chosen]
        lost = ~np.isin(previous.track, carried[carried >= 0])
        cand = chosen[carried < 0]
        if lost.any() and cand.size:
            track = track.copy()
            lost_ids, lost_win = previous.track[lost], previous.window[lost]
            win = leaves.window[cand, :-1]
            shared = ((win[:, None, :] == lost_win[None, :, :]) & (win[:, None, :] >= 0)).sum(2)
            ci, li = np.nonzero(shared)
            order = np.lexsort((lost_ids[li], leaves.tree[cand[ci]], -shared[ci, li]))
            taken_c, taken_l = np.zeros(cand.size, bool), np.zeros(lost_ids.size, bool)
            for c, k in zip(ci[order].tolist(), li[order].tolist(), strict=True):
                if taken_c[c] or taken_l[k]:
                    continue
                taken_c[c] = taken_l[k] = True
                tid = lost_ids[k]
                track[track == tid] = -1  # the old tree gives the id up
                track[leaves.tree == leaves.tree[cand[c]]] = tid
        cfg = self.config
        confirm = leaves.score >= self.confirm_threshold
        if cfg.confirm_hits > 0:
            hits = (leaves.window >= 0).sum(axis=1)
            confirm |= (hits >= cfg.confirm_hits) & (leaves.score > cfg.confirm_min_score)
        confirm &= leaves.n_updates >= cfg.confirm_min_plots
        new = leaves.chosen & (track < 0) & confirm
        if new.any():
            track = track.copy()
            trees = leaves.tree[new]  # one chosen leaf per tree, ascending
            ids = np.arange(self._next_track, self._next_track + trees.size, dtype=np.int64)
            self._next_track += trees.size
            j = np.minimum(np.searchsorted(trees, leaves.tree), trees.size - 1)
            hit = trees[j] == leaves.tree
            track[hit] = ids[j[hit]]
        return leaves if track is leaves.track else replace(leaves, track=track)

    def _report(self, scan: Scan, leaves: Leaves) -> TrackTable:
        """Confirmed tracks of the best hypothesis, ordered by track id."""
        sel = np.flatnonzero(leaves.chosen & (leaves.track >= 0))
        sel = sel[np.argsort(leaves.track[sel], kind="stable")]
        x = leaves.x[sel]
        n = sel.size
        return TrackTable(
            scan=np.full(n, int(scan.index), np.int64),
            time=np.full(n, float(scan.time)),
            track_id=leaves.track[sel],
            x=x[:, 0].copy(),
            y=x[:, 2].copy(),
            vx=x[:, 1].copy(),
            vy=x[:, 3].copy(),
            plot=leaves.window[sel, -1].copy(),
            score=leaves.score[sel].copy(),
            P=leaves.P[sel].copy(),
            tentative=np.zeros(n, bool),
        )

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | PathLike[str]) -> None:
        """Write the full state to one ``.npz`` (no pickle): the leaf arrays, the
        bookkeeping and configuration as a JSON string, and the clutter estimator's
        ``get_state()`` (its arrays stored as arrays)."""
        arrays: dict[str, np.ndarray] = {
            f"leaves__{k}": v for k, v in self._leaves.arrays().items()
        }
        if self._birth is not None:
            arrays.update({f"birth__{k}": v for k, v in self._birth.arrays().items()})
        arrays.update({f"history__{k}": v for k, v in self._history.arrays().items()})
        clutter_state = _encode(self.clutter.get_state(), arrays)
        meta = {
            "format": FORMAT,
            "config": json.loads(self.config.to_json()),
            "clutter_name": self.clutter.name,
            "clutter_state": clutter_state,
            "last_time": self._last_time,
            "last_index": self._last_index,
            "next_tree": self._next_tree,
            "next_track": self._next_track,
            "next_node": self._next_node,
        }
        arrays["meta"] = np.array(json.dumps(meta, sort_keys=True))
        with open(path, "wb") as f:
            np.savez(f, **arrays)  # type: ignore[arg-type]

    @classmethod
    def load(
        cls, path: str | PathLike[str], clutter: ClutterEstimator | None = None
    ) -> MHTTracker:
        """Restore a tracker written by :meth:`save`. ``clutter`` is an estimator of the
        same kind (its state is overwritten); it may be omitted for the ``known`` one."""
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        meta = json.loads(str(arrays.pop("meta")))
        if meta.get("format") != FORMAT:
            raise ValueError(f"{path}: not an MHT tracker state ({meta.get('format')!r})")
        if clutter is None:
            if meta["clutter_name"] != KnownClutter.name:
                raise ValueError(
                    f"{path}: saved with clutter estimator {meta['clutter_name']!r}; "
                    "pass one of that kind as clutter="
                )
            clutter = KnownClutter()
        elif clutter.name != meta["clutter_name"]:
            raise ValueError(
                f"{path}: saved with clutter estimator {meta['clutter_name']!r}, "
                f"got {clutter.name!r}"
            )
        clutter.set_state(_decode(meta["clutter_state"], arrays))
        trk = cls(MHTConfig.from_json(json.dumps(meta["config"])), clutter)
        trk._leaves = Leaves.from_arrays(
            {k.removeprefix("leaves__"): v for k, v in arrays.items() if k.startswith("leaves__")}
        )
        trk._last_time = meta["last_time"]
        trk._last_index = meta["last_index"]
        trk._next_tree = int(meta["next_tree"])
        trk._next_track = int(meta["next_track"])
        trk._next_node = int(meta["next_node"])
        trk._history.set_arrays(
            {k.removeprefix("history__"): v for k, v in arrays.items()
             if k.startswith("history__")})
        if trk._birth is not None:
            trk._birth.set_arrays(
                {k.removeprefix("birth__"): v for k, v in arrays.items() if k.startswith("birth__")}
            )
        return trk


@dataclass(frozen=True, slots=True)
class _Reported:
    """Track ids reported at the previous scan and their plots at scans ``k−N … k−1``
    (window shifted to the current scan's columns ``0 … N−1``)."""

    track: np.ndarray
    window: np.ndarray

    @classmethod
    def of(cls, leaves: Leaves) -> _Reported:
        rep = leaves.chosen & (leaves.track >= 0)
        return cls(leaves.track[rep], leaves.window[rep, 1:])


def _plots_in_confirmed_gates(
    leaves: Leaves, gated: kalman.Gated, n_plots: int
) -> np.ndarray | None:
    """Mask of plots inside the gate of a confirmed track reported at the last scan, or
    ``None`` when there is none (the clutter estimator's ``in_track_gates``)."""
    reported = leaves.chosen & (leaves.track >= 0)
    if not reported.any():
        return None
    mask = np.zeros(n_plots, bool)
    mask[gated.plot[reported[gated.track]]] = True
    return mask


def _encode(obj: Any, arrays: dict[str, np.ndarray]) -> Any:
    """JSON-able copy of ``obj`` with every ndarray moved into ``arrays``."""
    if isinstance(obj, np.ndarray):
        if obj.dtype.hasobject:
            raise ValueError("clutter state arrays must not hold Python objects")
        key = f"clutter__{len(arrays)}"
        arrays[key] = obj
        return {"__ndarray__": key}
    if isinstance(obj, dict):
        if not all(isinstance(k, str) for k in obj):
            raise ValueError("clutter state dict keys must be strings")
        return {k: _encode(v, arrays) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_encode(v, arrays) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def _decode(obj: Any, arrays: dict[str, np.ndarray]) -> Any:
    if isinstance(obj, dict):
        if set(obj) == {"__ndarray__"}:
            return arrays[obj["__ndarray__"]]
        return {k: _decode(v, arrays) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_decode(v, arrays) for v in obj]
    return obj
