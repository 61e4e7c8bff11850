"""The track-oriented MHT (P1 §1.3, Fig. 1): one call of :meth:`MHTTracker.step` per scan.

The tracking cycle, one stage per line of :meth:`MHTTracker.step`::

    validate         validate.validate_scan          the scan at the library boundary
    coverage         coverage.Coverage               P_D of each leaf (0: sensor did not look)
    looked-at trees  timed.split_looked              trees the frame steps; others carried
    predict          predict.predict_leaves          all leaves to the scan time (motion model)
    gate             timed.gate_looked               every leaf against every plot (each at
                                                       its plot's own time), ln p(z|T)
    clutter          intensity.clutter_intensity     κ̂(z) of the scan's plots (estimator)
    score            scoring.update_increment        ΔL of every gated pair
    extend trees     extend.propose_children         miss + one child per gated plot
    propose births   births.Birth.propose            new trees' first leaves (birth process)
    prune children   pruning.prune_children          SPRT deletion, score drop, caps — before
                                                     the (costly) update
    grow             extend.grow_children            the children's filter update
    seed births      births.Birth.seed               the new trees, with tree ids
    number nodes,    numbering.number_and_merge      leaf ids for the history links; the
    merge                                              trees the frame did not step back
    global hyp.      hypothesis.best_hypothesis      clusters → best compatible leaves
    N-scan pruning   pruning.prune_after_solve       decide scan k − N; cap on trees
    hand over        identity.hand_over              a track follows its plots
    confirm          sprt.SPRT.confirms,             SPRT (or M-of-N) confirmation → new
                     identity.confirm                  track ids
    backfill         history.TentativeHistory        the tentative past of new tracks
    forget           Birth.forget_used,              the confirmed tracks' plots leave the
                     ClutterEstimator.forget           birth window and the estimator's
    report           report.report, StepStats        confirmed tracks of the best hypothesis
    caps             caps.scan_config, CapWarnings   limits scaled to the scan's plots and
                                                     tracks; log the hard caps that acted

The motion model (:class:`~mhtrack.models.motion.MotionModel`: CV or IMM), the clutter
estimator (:class:`~mhtrack.clutter.base.ClutterEstimator`), the birth process
(:class:`~mhtrack.mht.births.base.Birth`) and the sensors' coverage
(:class:`~mhtrack.mht.coverage.Coverage`) are parts passed in; saving and restoring is
:mod:`mhtrack.mht.state`. Synchronous scans are the special case of frames whose plots
all have the frame's time and whose sensor looks at every leaf (``docs/mht.md``,
*Asynchronous plots*).
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from os import PathLike
from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.known import KnownClutter
from mhtrack.mht.births import Birth, default_birth
from mhtrack.mht.caps import SCALED, CapWarnings, scan_config, scene_leaves, solver_caps
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.coverage import Coverage, Everywhere, Looks
from mhtrack.mht.extend import grow_children, propose_children
from mhtrack.mht.gating import Gate, plots_in_confirmed_gates
from mhtrack.mht.history import TentativeHistory
from mhtrack.mht.hypothesis import best_hypothesis
from mhtrack.mht.identity import Reported, confirm, hand_over, newly_confirmed
from mhtrack.mht.intensity import clutter_intensity
from mhtrack.mht.numbering import Counter, number_and_merge
from mhtrack.mht.predict import predict_leaves
from mhtrack.mht.pruning import prune_after_solve, prune_children, removed_after_solve
from mhtrack.mht.report import StepStats, confirmed_windows, report
from mhtrack.mht.scoring import miss_increment, miss_increments, update_increment
from mhtrack.mht.sprt import SPRT
from mhtrack.mht.state import load_state, located, save_state
from mhtrack.mht.timed import gate_looked, split_looked
from mhtrack.mht.tree import Leaves, contains
from mhtrack.mht.validate import validate_scan
from mhtrack.models.motion import MotionModel
from mhtrack.records import PlotTable, Scan, TrackTable


class MHTTracker:
    """Track-oriented multiple hypothesis tracker with pluggable parts.

    Parameters
    ----------
    config : tracker parameters (:class:`MHTConfig`; defaults from P1 §3).
    clutter : the clutter estimator giving ``κ̂(z)``; default a known constant
        ``κ = 1e−9`` per m² (P1's plain MHT).
    motion : the motion model; default :attr:`MHTConfig.motion` (the IMM, or a single
        constant-velocity model when ``imm_sigma_v = 0``).
    birth : the birth process (:func:`mhtrack.build.make_birth` builds the one
        ``config.birth`` names); default P1's every-plot birth
        (:func:`~mhtrack.mht.births.default_birth`).
    coverage : the sensors' coverage (:mod:`mhtrack.mht.coverage`); default
        :class:`~mhtrack.mht.coverage.Everywhere` with ``config.p_detection`` (every leaf
        looked at every scan: P1's scans).

    Examples
    --------
    >>> trk = MHTTracker(MHTConfig(), KnownClutter(6.25e-7))
    >>> tracks = trk.run(plot_table)          # doctest: +SKIP
    >>> out = trk.step(scan); trk.last_stats  # doctest: +SKIP
    """

    def __init__(
        self, config: MHTConfig | None = None, clutter: ClutterEstimator | None = None, *,
        motion: MotionModel | None = None, birth: Birth | None = None,
        coverage: Coverage | None = None,
    ) -> None:
        self.config = cfg = MHTConfig() if config is None else config
        self.clutter: ClutterEstimator = KnownClutter() if clutter is None else clutter
        self.motion: MotionModel = cfg.motion if motion is None else motion
        self.coverage: Coverage = Everywhere(cfg.p_detection) if coverage is None else coverage
        self.birth: Birth = (default_birth(cfg, self.motion, self.coverage.plot_pd)
                             if birth is None else birth)
        #: How :func:`mhtrack.build.make_tracker` made this tracker (JSON-able), saved
        #: with its state so that :func:`mhtrack.build.load_tracker` can rebuild its
        #: parts; ``None`` for a tracker assembled by hand.
        self.recipe: dict[str, Any] | None = None
        self.sprt = SPRT.from_config(cfg)
        self.gate = Gate(cfg.gate_probability, cfg.max_gated_pairs)
        self._R = np.eye(2) * cfg.sigma_w**2
        self._miss_pg = cfg.gate_probability if cfg.miss_uses_gate_probability else None
        self._leaves = Leaves.empty(cfg.n_scan + 1, self.motion.n_models)
        self._last_time: float | None = None
        self._last_index: int | None = None
        self.trees, self.tracks, self.nodes = Counter(), Counter(), Counter()
        self._history = TentativeHistory(cfg.history_scans)
        self._cap_warnings = CapWarnings()
        self.last_stats: StepStats | None = None
        #: Rows, at earlier scans, of the tracks confirmed by the last :meth:`step`: their
        #: tentative past (``tentative`` true; :mod:`mhtrack.mht.history`).
        self.last_backfill: TrackTable = TrackTable.empty()

    @property
    def leaves(self) -> Leaves:
        """The current hypothesis store (read-only view for inspection and tests)."""
        return self._leaves

    def step(self, scan: Scan) -> TrackTable:
        """Process one scan (or frame) through the module docstring's cycle; return the
        confirmed tracks of the best global hypothesis. Statistics go to :attr:`last_stats`,
        the earlier rows of tracks confirmed now to :attr:`last_backfill`."""
        t0 = time.perf_counter()
        cfg, ftime = self.config, float(scan.time)
        caps: dict[str, int] = {}
        z, R, rows = validate_scan(scan, self._R, self._last_time, self._last_index)
        on_air = self._leaves.reported()  # the tracks reported at the last scan
        n_tracks = int(np.count_nonzero(on_air))
        lim = scan_config(cfg, len(z), n_tracks)  # caps scaled to the scan
        self.gate.max_pairs = lim.max_gated_pairs
        self.birth.limit(lim.max_births_per_scan)
        by_id = self.coverage.per_tree_looks
        previous = Reported.of(self._leaves, by_id=by_id, reported=on_air)
        leaves, looks, idle = self._look(scan)
        pred = predict_leaves(self.motion, leaves, ftime)
        gated, pair_pred = gate_looked(self.gate, leaves, pred,
                                       None if looks.uniform is not None else looks.pd,
                                       z, R, scan.t, ftime, self.motion, caps)
        in_gates = plots_in_confirmed_gates(leaves, gated, len(z))
        kappa = clutter_intensity(self.clutter, scan, z, in_gates, cfg.min_clutter_density)
        update_dl = update_increment(gated.loglik, kappa, self.coverage.plot_pd(scan),
                                     cfg.new_target_density, gated.plot)
        children = propose_children(leaves, gated, self._miss(looks), update_dl)
        cand = self.birth.propose(scan, z, R, rows, kappa, in_gates, caps)
        children = prune_children(leaves, children, len(cand) + len(idle), self.sprt, lim,
                                  caps, scene_leaves(cfg, len(z), n_tracks))
        grown = grow_children(leaves, pred, children, z, R, rows, self.motion, ftime,
                              pair_pred, scan.t, gated.posterior)
        births = self.birth.seed(scan, cand, grown.window, self.trees, caps)
        first_node = self.nodes.next
        parts = (grown, births) if len(idle) == 0 and len(births) else None
        leaves = number_and_merge(grown, births, idle, self.nodes, parts is not None)
        hyp = best_hypothesis(leaves.score, leaves.tree, leaves.window, cfg.max_cluster_size,
                              cfg.milp_node_limit, by_id=by_id, n_best=cfg.n_best)
        solver_caps(hyp, caps)
        leaves = prune_after_solve(leaves, hyp.leaves, lim.max_trees, caps, by_id=by_id,
                                   remove=removed_after_solve(leaves, hyp, cfg), parts=parts)
        is_new = None if len(idle) == 0 else leaves.node >= first_node
        first_new = self.tracks.next
        leaves = hand_over(leaves, previous, by_id=by_id)
        leaves = confirm(leaves, self.sprt.confirms(leaves), self.tracks)
        self.last_backfill = self._history.backfill(leaves, newly_confirmed(leaves, first_new))
        rep = leaves.reported()
        self._history.record(int(scan.index), ftime, leaves, is_new, rep)
        self._forget(leaves, rows, rep)
        self._leaves, self._last_time, self._last_index = leaves, ftime, int(scan.index)
        out = report(scan, leaves, is_new, rep)
        limits = {k: getattr(lim, k) for k in SCALED}
        self.last_stats = StepStats.of(scan, len(z), leaves, births, hyp, out,
                                       time.perf_counter() - t0, caps, limits)
        self._cap_warnings(int(scan.index), caps, len(z), limits)
        return out

    def _look(self, scan: Scan) -> tuple[Leaves, Looks, Leaves]:
        """Coverage: each leaf's ``P_D`` in this frame; the leaves its sensor did not look
        at are set aside (``idle``) and carried unchanged."""
        lv = self._leaves
        return split_looked(lv, self.coverage.detection(scan, lv.x, lv.P, lv.time))

    def _miss(self, looks: Looks) -> float | np.ndarray:
        """The miss increments of the looked-at leaves: one value when every leaf was
        looked at alike (what :func:`miss_increments` then fills every row with)."""
        if looks.uniform is not None:
            return miss_increment(looks.uniform, self._miss_pg)
        return miss_increments(looks.miss_pd, self._miss_pg)

    def _forget(self, leaves: Leaves, rows: np.ndarray, rep: np.ndarray) -> None:
        """The plots the confirmed tracks used (``rep``: the leaves that report them)
        leave the birth process and the clutter estimator (their optional hooks)."""
        used = confirmed_windows(leaves, rep)
        self.birth.forget_used(used)
        self.clutter.forget(contains(used[:, -1], rows))

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

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | PathLike[str]) -> None:
        """Write the full state to one ``.npz`` (no pickle; :mod:`mhtrack.mht.state`)."""
        parts = {"leaves": self._leaves.arrays(), "birth": self.birth.arrays(),
                 "history": self._history.arrays(), "coverage": self.coverage.arrays()}
        save_state(path, parts, self.clutter, self.config, {
            "last_time": self._last_time, "last_index": self._last_index,
            "next_tree": self.trees.next, "next_track": self.tracks.next,
            "next_node": self.nodes.next,
            **({} if self.recipe is None else {"recipe": self.recipe})})

    @classmethod
    def load(
        cls, path: str | PathLike[str], clutter: ClutterEstimator | None = None, *,
        motion: MotionModel | None = None, birth: Birth | None = None,
        coverage: Coverage | None = None,
    ) -> MHTTracker:
        """Restore a tracker written by :meth:`save`. ``clutter`` is an estimator of the
        same kind (its state is overwritten); it may be omitted for the ``known`` one.
        ``motion``, ``birth`` and ``coverage`` as in the constructor (the saved birth and
        coverage states are loaded into them)."""
        saved = load_state(path, clutter)
        trk = cls(saved.config, saved.clutter, motion=motion, birth=birth, coverage=coverage)
        meta = saved.meta
        leaves = saved.part("leaves")
        trk._leaves = Leaves.from_arrays(leaves)
        if trk._leaves.n_models != trk.motion.n_models:
            raise ValueError(f"{path}: saved with {trk._leaves.n_models} IMM models, the "
                             f"motion model given has {trk.motion.n_models}")
        trk._last_time, trk._last_index = meta["last_time"], meta["last_index"]
        trk.trees, trk.tracks = Counter(meta["next_tree"]), Counter(meta["next_track"])
        trk.nodes = Counter(meta["next_node"])
        for part, owner in (("history", trk._history), ("birth", trk.birth),
                            ("coverage", trk.coverage)):
            with located(path, f"{part}__*"):
                owner.set_arrays(saved.part(part))
        return trk
