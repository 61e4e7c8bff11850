"""The track-oriented MHT (P1 §1.3, Fig. 1): one call of :meth:`MHTTracker.step` per scan.

The tracking cycle, one stage per line of :meth:`MHTTracker.step`, each given the frame's
context (:class:`~mhtrack.mht.context.FrameContext`: validated plots, scaled limits, the
tracks on air, the caps' counters) where it needs more than its own arrays::

    validate    validate.validate_scan,         the scan at the library boundary; limits
                context.FrameContext.of           scaled to its plots and tracks (caps)
    look        coverage.Coverage,              P_D of each leaf (0: sensor did not look);
                timed.split_looked                trees the frame steps, others carried
    predict     predict.predict_leaves          all leaves to the scan time (motion model)
    gate        timed.gate_looked               every leaf against every plot (each at
                                                  its plot's own time), ln p(z|T)
    clutter     intensity.clutter_intensity     κ̂(z) of the scan's plots (estimator)
    score       scoring.update_increment        ΔL of every gated pair
    propose     extend.propose_children,        miss + one child per gated plot; new
                births.Birth.propose              trees' first leaves (birth process)
    prune       pruning.prune_children          SPRT deletion, score drop, caps — before
                                                  the (costly) update
    grow        extend.grow_children            the children's filter update
    births      births.Birth.seed,              the new trees, with tree ids; leaf ids for
                carry.number_frame                the history links; idle trees merged back
    hypothesis  frame_scope.FrameScope.solve    clusters → best compatible leaves (the
                                                  groups of trees the frame touched)
    prune       pruning.kept_after_solve,       N-scan: decide scan k − N (in that
                pruning.take_kept                 scope); cap on trees; states copied once
    confirm     identity.hand_over,             a track follows its plots; SPRT (or
                sprt.SPRT.confirms,               M-of-N) confirmation → new track ids;
                history.TentativeHistory          the tentative past of new tracks
    report      report.report, StepStats,       the confirmed tracks' plots leave the
                Birth.forget_used,                birth window and the estimator's; the
                ClutterEstimator.forget,          confirmed tracks of the best hypothesis;
                caps.CapWarnings                  log the hard caps that acted

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
from dataclasses import replace
from os import PathLike
from typing import Any

import numpy as np

from mhtrack.attributes import PlotAttributes
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.known import KnownClutter
from mhtrack.mht.attribute_scores import (
    AttributeModel,
    grow_attributes,
    pair_increments,
    positions,
    reply_terms,
    seed_attributes,
)
from mhtrack.mht.births import Birth, default_birth
from mhtrack.mht.births.same_address import untracked
from mhtrack.mht.caps import CapWarnings
from mhtrack.mht.carry import Carried, Merged, number_frame
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.context import FrameContext
from mhtrack.mht.coverage import Coverage, Everywhere, Looks
from mhtrack.mht.extend import grow_children, propose_children
from mhtrack.mht.frame_scope import FrameScope
from mhtrack.mht.gating import Gate, plots_in_confirmed_gates
from mhtrack.mht.history import TentativeHistory
from mhtrack.mht.identity import Reported, confirm, hand_over, newly_confirmed
from mhtrack.mht.intensity import clutter_intensity
from mhtrack.mht.numbering import Counter
from mhtrack.mht.predict import predict_leaves
from mhtrack.mht.pruning import kept_after_solve, prune_children, removed_after_solve, take_kept
from mhtrack.mht.report import StepStats, confirmed_windows, report
from mhtrack.mht.resume import AddressBook
from mhtrack.mht.scoring import miss_increment, miss_increments, update_increment
from mhtrack.mht.sensor_ages import SensorAges
from mhtrack.mht.sprt import SPRT
from mhtrack.mht.state import load_state, located, save_state
from mhtrack.mht.timed import gate_looked, split_looked
from mhtrack.mht.track_attributes import Callsigns, says_anything, track_attributes
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
    attributes : the likelihood ratios of plots' codes, addresses and flight levels
        (:mod:`mhtrack.mht.attribute_scores`); default :class:`AttributeModel`'s. Plots
        without attributes are scored by position alone, as in P1.

    Examples
    --------
    >>> trk = MHTTracker(MHTConfig(), KnownClutter(6.25e-7))
    >>> tracks = trk.run(plot_table)          # doctest: +SKIP
    >>> out = trk.step(scan); trk.last_stats  # doctest: +SKIP
    """

    def __init__(
        self, config: MHTConfig | None = None, clutter: ClutterEstimator | None = None, *,
        motion: MotionModel | None = None, birth: Birth | None = None,
        coverage: Coverage | None = None, attributes: AttributeModel | None = None,
    ) -> None:
        self.attributes = AttributeModel() if attributes is None else attributes
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
        self.gate = Gate(cfg.gate_probability)
        self._R = np.eye(2) * cfg.sigma_w**2
        self._miss_pg = cfg.gate_probability if cfg.miss_uses_gate_probability else None
        self._leaves = Leaves.empty(cfg.n_scan + 1, self.motion.n_models)
        self._last_time: float | None = None
        self._last_index: int | None = None
        self.trees, self.tracks, self.nodes = Counter(), Counter(), Counter()
        self._history = TentativeHistory(cfg.history_scans)
        self._cap_warnings = CapWarnings()
        self._book = AddressBook(self.attributes.resume_s)
        self._callsigns = Callsigns(self.attributes.resume_s)
        self._ages = SensorAges(self.attributes.resume_s)
        #: The solve stage over the groups of trees a frame touched
        #: (:mod:`mhtrack.mht.frame_scope`; ``scope.enabled = False``: all at every frame).
        self.scope = FrameScope(cfg, self.coverage.per_tree_looks)
        self.last_stats: StepStats | None = None
        #: The clutter intensity κ̂ (per m² per scan, floored) the last :meth:`step` scored
        #: each of its plots with (kept for the pipeline's DEBUG line, not recomputed).
        self.last_kappa: np.ndarray = np.empty(0)
        #: Rows, at earlier scans, of the tracks confirmed by the last :meth:`step`: their
        #: tentative past (``tentative`` true; :mod:`mhtrack.mht.history`).
        self.last_backfill: TrackTable = TrackTable.empty()

    @property
    def keep_models(self) -> bool:
        """Whether every reported and backfilled row carries its leaf's model states
        (``TrackTable.mu, xm, Pm``: what :mod:`mhtrack.models.smoother` needs of an IMM);
        off by default (rows are as small as before)."""
        return self._history.models

    @keep_models.setter
    def keep_models(self, on: bool) -> None:
        self._history.models = bool(on)

    @property
    def leaves(self) -> Leaves:
        """The current hypothesis store (read-only view for inspection and tests)."""
        return self._leaves

    @property
    def last_time(self) -> float | None:
        """The time of the last scan stepped (``None`` before the first)."""
        return self._last_time

    def step(self, scan: Scan) -> TrackTable:
        """Process one scan (or frame) through the module docstring's cycle; return the
        confirmed tracks of the best global hypothesis. Statistics go to :attr:`last_stats`,
        the earlier rows of tracks confirmed now to :attr:`last_backfill`."""
        t0 = time.perf_counter()
        f = self._frame(scan)
        leaves, looks, idle = self._look(scan)
        pred = predict_leaves(self.motion, leaves, f.time)
        gated, pair_pred = gate_looked(f, self.gate, leaves, pred, looks=looks,
                                       motion=self.motion)
        in_gates = plots_in_confirmed_gates(leaves, gated, f.n_plots)
        kappa = clutter_intensity(self.clutter, f, in_gates, self.config.min_clutter_density)
        self.last_kappa = kappa
        lam = self.birth.scan_density(f, kappa)
        lam = self.config.new_target_density if lam is None else lam
        update_dl = update_increment(gated.loglik, kappa, self.coverage.plot_pds(scan), lam,
                                     gated.plot)
        attrs = scan.attrs if scan.attrs is not None and scan.attrs.any() else None
        if attrs is not None:
            reply = reply_terms(self.attributes, attrs, kappa, lam)
            update_dl = update_dl + reply[gated.plot] + pair_increments(
                self.attributes, leaves.level, leaves.ident, attrs, scan.plot_times(),
                gated.track, gated.plot)
        children = propose_children(leaves, gated, self._miss(looks), update_dl)
        cand = self.birth.propose(f, kappa, in_gates)
        if attrs is not None and len(cand) and f.rows.size:
            gain = np.where((j := positions(f.rows, cand.window[:, -1])) >= 0,
                            reply[j], 0.0)
            cand = replace(cand, score=cand.score + gain, peak=cand.peak + gain)
        children = prune_children(f, leaves, children, self.sprt,
                                  n_births=len(cand) + len(idle))
        if attrs is not None and not self.attributes.birth_on_tracked_address:
            children, cand = untracked(children, cand, f.rows, attrs.address, leaves)
        grown = grow_children(f, leaves, pred, children, motion=self.motion,
                              pair_pred=pair_pred, posterior=gated.posterior)
        births = self.birth.seed(f, cand, grown.window, self.trees)
        if attrs is not None:
            grown, births = self._attributes(f, attrs, grown, births, children.plot)
        leaves, parts, first_node = self._number(grown, births, idle)
        hyp, scope = self.scope.solve(f, leaves, first_node)
        kept = kept_after_solve(f, leaves, hyp.leaves, by_id=self.coverage.per_tree_looks,
                                scope=scope, remove=removed_after_solve(leaves, hyp, self.config))
        solved, leaves = leaves, take_kept(leaves, kept, hyp.leaves, parts)
        self.scope.pruned(solved, leaves, kept)
        stepped = None if len(idle) == 0 else leaves.node >= first_node
        leaves = self._confirm(f, leaves)
        out = self._report(f, leaves, stepped)
        self.last_stats = StepStats.of(f, leaves, births=births, hyp=hyp, out=out,
                                       time_s=time.perf_counter() - t0)
        self._cap_warnings(f.index, f.caps, f.n_plots, self.last_stats.limits)
        return out

    # ------------------------------------------------------------------ stages
    def _frame(self, scan: Scan) -> FrameContext:
        """Validate: the frame's context (:class:`~mhtrack.mht.context.FrameContext`) — its
        plots, the tracks reported at the last frame and the limits scaled to both; the
        birth process is told its limit."""
        plots = validate_scan(scan, self._R, self._last_time, self._last_index)
        previous = Reported.of(self._leaves, by_id=self.coverage.per_tree_looks)
        frame = FrameContext.of(scan, plots, config=self.config, previous=previous,
                                n_sensors=self.coverage.n_sensors)
        self.birth.limit(frame.limits.max_births_per_scan)
        return frame

    def _look(self, scan: Scan) -> tuple[Leaves, Looks, Carried | Leaves]:
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

    def _attributes(self, frame: FrameContext, attrs: PlotAttributes, grown: Leaves,
                    births: Leaves, plot: np.ndarray) -> tuple[Leaves, Leaves]:
        """The grown leaves' and new trees' vertical states, codes and addresses
        (:mod:`mhtrack.mht.attribute_scores`): children from their plots (``plot``, ``-1``
        a miss), new trees from the plot of the frame they start with."""
        t = frame.scan.plot_times()
        level, ident = grow_attributes(self.attributes, grown.level, grown.ident, attrs,
                                       t, plot)
        grown = replace(grown, level=level, ident=ident)
        if len(births) and frame.rows.size:
            j = positions(frame.rows, births.window[:, -1])
            level, ident = seed_attributes(self.attributes, attrs, t, j)
            births = replace(births, level=level, ident=ident)
        return grown, births

    def _number(self, grown: Leaves, births: Leaves, idle: Carried | Leaves
                ) -> tuple[Leaves, tuple[Leaves, Leaves] | Merged | None, int]:
        """Node ids for the new leaves (the history's links) and the idle trees merged
        back: ``(leaves, parts, first new node id)``; ``parts`` what the states ``leaves``
        defers are copied from at pruning (:func:`~mhtrack.mht.carry.number_frame`)."""
        first_node = self.nodes.next
        return *number_frame(grown, births, idle, self.nodes), first_node

    def _confirm(self, frame: FrameContext, leaves: Leaves) -> Leaves:
        """Hand over track ids that follow their plots, confirm by the SPRT (new track ids),
        and keep the tentative past of the tracks confirmed now (:attr:`last_backfill`)."""
        assert frame.previous is not None
        first_new = self.tracks.next
        leaves = hand_over(leaves, frame.previous, by_id=self.coverage.per_tree_looks)
        confirms = self._book.one_per_address(leaves, self.sprt.confirms(leaves))
        leaves, resumed, last = self._book.resume(leaves, confirms)
        leaves = confirm(leaves, confirms, self.tracks)
        new = newly_confirmed(leaves, first_new)
        if resumed.size:
            new = (leaves.chosen & ((leaves.track >= first_new)
                                    | contains(resumed, leaves.track))).nonzero()[0]
        back = self._history.backfill(leaves, new)
        if resumed.size and len(back):  # a resumed id's past: only after its last report
            k = np.searchsorted(resumed, back.track_id, sorter=np.argsort(resumed))
            k = np.argsort(resumed)[np.minimum(k, resumed.size - 1)]
            old = (resumed[k] == back.track_id) & (back.time <= last[k])
            back = back.take(~old)
        self.last_backfill = back
        return leaves

    def _report(self, frame: FrameContext, leaves: Leaves,
                stepped: np.ndarray | None) -> TrackTable:
        """Record the frame in the history, let the birth process and the clutter estimator
        forget the confirmed tracks' plots, keep ``leaves`` for the next frame; the
        confirmed tracks of the best hypothesis that the frame ``stepped`` (mask;
        ``None``: all)."""
        rep = leaves.reported()
        self._history.record(frame.index, frame.time, leaves, stepped, rep, frame.scan)
        self._book.record(leaves, rep, frame.time)
        self._forget(leaves, frame.rows, rep)
        self._leaves, self._last_time, self._last_index = leaves, frame.time, frame.index
        attrs = frame.scan.attrs
        identity = None if not says_anything(attrs, leaves) else lambda sel: \
            track_attributes(leaves, sel, attrs, frame.rows, self._callsigns, frame.time,
                             sensor=frame.scan.sensor, plot_t=frame.scan.plot_times(),
                             ages=self._ages)
        return report(frame.scan, leaves, stepped, rep, identity=identity,
                      models=self._history.models)

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
    def save(self, path: str | PathLike[str], extra: dict[str, Any] | None = None) -> None:
        """Write the full state to one ``.npz`` (no pickle; :mod:`mhtrack.mht.state`);
        ``extra``: the caller's JSON-able bookkeeping, saved with it (``meta["extra"]``,
        e.g. a live run's frame number and time axis)."""
        parts = {"leaves": self._leaves.arrays(), "birth": self.birth.arrays(),
                 "history": self._history.arrays(), "coverage": self.coverage.arrays(),
                 "addresses": self._book.arrays(),
                 **({"callsigns": self._callsigns.arrays()} if self._callsigns.track.size
                    else {}),
                 **({"ages": self._ages.arrays()} if self._ages.track.size else {})}
        save_state(path, parts, self.clutter, self.config, {
            "last_time": self._last_time, "last_index": self._last_index,
            "next_tree": self.trees.next, "next_track": self.tracks.next,
            "next_node": self.nodes.next,
            **({} if self.recipe is None else {"recipe": self.recipe}),
            **({} if extra is None else {"extra": extra})})

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
                            ("coverage", trk.coverage), ("addresses", trk._book),
                            ("callsigns", trk._callsigns), ("ages", trk._ages)):
            with located(path, f"{part}__*"):
                owner.set_arrays(saved.part(part))
        return trk
