"""Parameters of the track-oriented MHT, each with its default and where it comes from.

Values that P1 §3 gives are taken from it; the rest are our documented choices (see
``docs/mht.md`` for the reasoning behind each).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, fields
from typing import Any

from mhtrack.bounds import float_problem, int_problem
from mhtrack.models.imm import CVModelSet
from mhtrack.models.motion import ConstantVelocity, MotionModel
from mhtrack.names import BIRTHS, EVERY_PLOT

#: Largest N-scan depth: every leaf keeps ``N + 1`` plot ids and the trees grow with ``N``;
#: deeper than this only costs memory (P1 uses 3).
MAX_N_SCAN = 20
#: Largest tentative history kept (scans).
MAX_HISTORY_SCANS = 1000
#: Largest number of best global hypotheses enumerated per cluster.
MAX_N_BEST = 1000
#: Fields of older versions ignored when read back (``milp_time_limit``: a wall-clock limit,
#: replaced by the deterministic ``milp_node_limit``).
REMOVED_FIELDS = ("milp_time_limit",)


@dataclass(frozen=True)
class MHTConfig:
    """Configuration of :class:`~mhtrack.mht.tracker.MHTTracker`.

    Built by hand or read from a state, every number is checked when the object is made:
    first against :mod:`mhtrack.bounds` (finite within ±1e15, integers within ±2^53),
    then against its own range below; a ``ValueError`` names the field
    (``MHTConfig.sigma_w: 1e+308 is out of range (...)``, ``docs/errors.md``).

    Parameters
    ----------
    p_detection : ``P_D``, probability that a target yields a plot per scan. Default 0.9
        (P1 §3).
    new_target_density : ``λ_v``, density of new targets (per m² per scan) in the score
        denominator ``κ̂ + λ_v`` (P1 eq. 5) and the birth score. Default 1e−7 (P1 §3).
    startup_density : score each scan's plots and births with the density of targets not
        yet detected instead of the constant ``new_target_density`` ``λ_v``: estimated
        at the first scan from the plots in excess of the clutter, then decayed by
        ``1 − P_D`` a scan with ``λ_v`` added (the PMBM filter's undetected-target
        intensity, :mod:`mhtrack.mht.undetected`), so that a tracker started on a busy sky
        knows that every target present is new. Only with ``birth = "every-plot"``.
        Default False (P1's constant ``λ_v``).
    sigma_w : Cartesian measurement noise std (m), ``R = σw² I`` for plots without their
        own covariance. Default 100 (P1 §3, ``σw² = 10⁴``).
    sigma_v : process (acceleration) noise std of the constant-velocity model (m/s²).
        Default 10 (P1 §3, ``σv² = 100``). With an IMM, the manoeuvre model's.
    imm_sigma_v : acceleration noise std (m/s²) of a second, *quiet* constant-velocity
        model; when > 0 each track is an IMM of the quiet and the ``sigma_v`` models
        (:mod:`mhtrack.models.imm`), when 0 a single CV model with ``sigma_v`` (P1's).
        Default 1 (ours, measured in ``docs/mht.md``, *Motion model*).
    imm_mode_time : mean time (s) a target stays in one IMM model, ``π_ii = exp(−dt/τ)``.
        Default 100 (our choice).
    gate_probability : ``P_G``, probability a target's plot falls in the χ² (2 d.o.f.)
        gate. Default 0.999 (our choice: γ ≈ 13.8, a true plot is almost never lost).
    miss_uses_gate_probability : score a miss as ``ln(1 − P_D·P_G)`` (exact when a plot
        outside the gate is possible) instead of P1 eq. 5's ``ln(1 − P_D)``. Default
        False (P1).
    v_max : largest target speed (m/s); a new tree starts with velocity 0 and velocity
        variance ``(v_max/2)²`` per axis. Default 300 (our choice: covers airliners; the
        P1/P2 targets move at ≤ 200 m/s, within 1.4 σ).
    n_scan : depth ``N`` of N-scan pruning; leaves remember their plots over the last
        ``N + 1`` scans. Default 3 (P1 §3).
    defer_tentative : N-scan pruning does not commit a tentative tree to its chosen
        branch (no decision at ``k − N`` within the tree) until the tree is confirmed; its
        branches are still removed when another tree of the best hypothesis holds their
        plot at ``k − N``, and bounded by SPRT deletion, ``prune_drop`` and the caps
        (:func:`~mhtrack.mht.pruning.n_scan_keep`'s ``defer``). Default False (P1: every
        tree in the best hypothesis is committed).
    alpha : SPRT false-confirmation probability. Default 0.02 (our choice, measured in
        ``docs/mht.md``, *Motion model*: lowest mean OSPA on uniform clutter with the true
        κ within 0.3 m of α = 0.03, which confirms more clutter where the clutter drifts).
    beta : SPRT true-deletion probability. Default 1e−4 (our choice). Confirm at
        ``L ≥ ln((1−β)/α)`` ≈ 3.9, delete at ``L − L_peak ≤ ln(β/(1−α))`` ≈ −9.2, i.e. four
        consecutive misses at ``P_D = 0.9`` (Wald 1947; Blackman & Popoli 1999 §6.2).
    confirm_min_plots : a tree is confirmed only once the chosen branch holds at least this
        many plots. Default 2 (our choice: a single plot says nothing of a velocity; the
        birth score ``ln(λ_v P_D/(κ̂ + λ_v)) ≤ ln P_D < 0`` is below every SPRT confirmation
        threshold ``ln((1−β)/α) > 0``, so this now matters only for logic confirmation,
        ``confirm_hits``).
    confirm_hits : logic confirmation, ``M`` of an M-of-N rule over the ``N + 1`` scans of
        the leaf's window: a tentative tree is also confirmed when its chosen leaf used
        plots in at least ``confirm_hits`` of its last ``n_scan + 1`` scans **and** its
        score exceeds ``confirm_min_score``. Default 0 = off (SPRT only); 3 gives the classic
        3/4 logic with ``n_scan = 3`` (P2 §2.1). Measured on crossing with uniform clutter
        and the true κ (20 seeds): it confirms sooner but lets short clutter-chain tracks
        through (``docs/mht.md``), so it is not the default. Combining score
        and M-of-N confirmation follows Blackman & Popoli 1999 §6.2–6.3: with
        ``P_D = 0.9`` two misses among a new target's first scans cost ``2·ln 0.1 ≈ −4.6``
        and hold the SPRT back for several scans although the plots say "target".
    confirm_min_score : the score the logic confirmation also requires. Default 0 (the
        track is more likely a target than clutter, likelihood ratio > 1); only used when
        ``confirm_hits > 0``.
    prune_drop : a leaf more than this below its tree's best leaf is pruned before the
        global hypothesis is solved. Default 12 (a likelihood ratio of e¹² ≈ 1.6·10⁵).
    scale_caps : the caps ``max_births_per_scan``, ``max_trees``, ``max_leaves`` and
        ``max_gated_pairs`` grow with the scan's plots and confirmed tracks, the values
        below being their floors (:func:`mhtrack.mht.caps.scaled_limits`; unchanged up to
        900 plots and 100 tracks per scan, bounded in a burst of over 20 000), and the
        overload rules cut the children to 4 per plot and 2 misses per tree where a leaf
        cap would act — those of every tree when the children exceed what the scan
        supports, else those of the tentative trees only (:mod:`mhtrack.mht.caps`).
        Default True; False: the values below at every scan, neither overload rule.
    max_leaves_per_tree : hard cap on the leaves of one tree (best scores kept).
        Default 300 (above the largest trees, ~290 leaves, of the crossing scenario with
        40 uniform clutter plots per scan and the true κ).
    max_leaves : hard cap on all leaves (confirmed trees' leaves first, then best scores).
        Default 20 000 (≈ 7× the leaves of the crossing scenario); scaled (``scale_caps``).
    max_trees : hard cap on trees (trees in the best hypothesis and confirmed trees first,
        then highest best-leaf score). Default 5 000; with ``scale_caps`` on, 5 000 per
        rotating sensor of the coverage (sector frames of several radars: the store holds
        every radar's trees; sensors without a period and fused scans count as one) and
        scaled (``scale_caps``); off: 5 000 whatever the sensors.
    max_gated_pairs : at most this many leaf–plot pairs are tested in the gates per scan;
        beyond it, leaves of confirmed trees and then the best-scoring leaves are gated
        first and the rest only get a miss child. Default 300 000; scaled (``scale_caps``).
    max_births_per_scan : at most this many plots of a scan start trees (plots outside
        confirmed tracks' gates first, then highest birth score). Default 2 000; scaled
        (``scale_caps``).
    max_cluster_size : clusters with more candidate (positive-score) leaves than this are
        solved greedily instead of exactly. Default 2 000.
    milp_node_limit : branch-and-bound nodes HiGHS may explore on one cluster's integer
        programme; then its best answer so far (or greedy's, if better) is used, counted
        as ``milp_node_limit`` in ``StepStats.caps``. A count, not a time: the same input
        gives the same answer on any machine and under any load. Default 1000 (our
        choice: the crossing clusters that reach the MILP are proven at its root node).
    birth : which plots start new trees (:mod:`mhtrack.mht.births`; one of
        :data:`mhtrack.names.BIRTHS`). ``"every-plot"`` (default,
        P1 Fig. 1): every plot, one-point initialisation. ``"logic"``, ``"modified-logic"``,
        ``"hough"``, ``"modified-hough"``: P2's initiator over a sliding window of the last
        4 scans; a tree starts only from each newly initiated track, seeded with its
        least-squares state, scored by the log-likelihood ratio of its plots.
    birth_theta_deg : angle limit ``θ`` of the modified initiators. Default 20 (P2 §2.2).
    history_scans : how many scans of tentative leaves the tracker keeps so that a track,
        once confirmed, can also be reported at the scans before — back to its first plot
        (to the seed scan with an initiator birth), at most this many scans
        (:mod:`mhtrack.mht.history`; ``MHTTracker.last_backfill``). Default 30 (our choice:
        longer than any tentative life we measured; 0 keeps nothing).
    min_clutter_density : floor on the estimator's ``κ̂(z)`` (per m²), so that a density
        estimate that underflows to 0 far from its components cannot give an infinite
        score. Default 1e−12 (our choice: 1000× below P1's plain-MHT κ = 1e−9).
    n_best : how many best global hypotheses of each cluster are enumerated (Murty's
        partitioning, :mod:`mhtrack.mht.murty`) for the track probabilities
        (:mod:`mhtrack.mht.track_probability`); the best one is still the one reported.
        Default 1 (only the best: every chosen leaf has probability 1).
    prune_probability : after the solve, leaves with a positive score whose probability
        over the ``n_best`` hypotheses is below this are removed (the chosen ones never).
        Default 0 = off. Only useful with ``n_best > 1``.
    merge_frames : merge duplicate branches: leaves whose plots (and misses) over their
        last ``merge_frames`` window columns are the same, at least one a plot, keep only
        the first by (chosen, confirmed, score, index) (:func:`mhtrack.mht.merging.merge_keep`).
        Default 0 = off; at most ``n_scan + 1``.
    """

    p_detection: float = 0.9
    new_target_density: float = 1e-7
    startup_density: bool = False
    sigma_w: float = 100.0
    sigma_v: float = 10.0
    imm_sigma_v: float = 1.0
    imm_mode_time: float = 100.0
    gate_probability: float = 0.999
    miss_uses_gate_probability: bool = False
    v_max: float = 300.0
    n_scan: int = 3
    defer_tentative: bool = False
    alpha: float = 0.02
    beta: float = 1e-4
    confirm_min_plots: int = 2
    confirm_hits: int = 0
    confirm_min_score: float = 0.0
    prune_drop: float = 12.0
    scale_caps: bool = True
    max_leaves_per_tree: int = 300
    max_leaves: int = 20_000
    max_trees: int = 5_000
    max_gated_pairs: int = 300_000
    max_births_per_scan: int = 2_000
    max_cluster_size: int = 2_000
    milp_node_limit: int = 1000
    min_clutter_density: float = 1e-12
    birth: str = "every-plot"
    birth_theta_deg: float = 20.0
    history_scans: int = 30
    n_best: int = 1
    prune_probability: float = 0.0
    merge_frames: int = 0

    def __post_init__(self) -> None:
        def check(name: str, ok: bool, what: str) -> None:
            if not ok:
                raise ValueError(f"MHTConfig.{name} must be {what}, got {getattr(self, name)!r}")

        for f in fields(self):  # mhtrack.bounds first: no later square or exp overflows
            v = getattr(self, f.name)
            if isinstance(v, int | float) and not isinstance(v, bool):
                problem = int_problem(v) if _is_int(v) else float_problem(v)
                if problem is not None:
                    raise ValueError(f"MHTConfig.{f.name}: {problem}")
        for name in ("p_detection", "gate_probability", "alpha", "beta"):
            v = getattr(self, name)
            check(name, isinstance(v, int | float) and 0.0 < v < 1.0, "in (0, 1)")
        check("alpha", self.alpha + self.beta < 1.0, "such that alpha + beta < 1")
        for name in ("new_target_density", "sigma_w", "v_max", "prune_drop",
                     "min_clutter_density", "imm_mode_time"):
            v = getattr(self, name)
            check(name, isinstance(v, int | float) and math.isfinite(v) and v > 0, "finite > 0")
        check(
            "sigma_v",
            isinstance(self.sigma_v, int | float) and math.isfinite(self.sigma_v)
            and self.sigma_v >= 0,
            "finite >= 0",
        )
        check(
            "imm_sigma_v",
            isinstance(self.imm_sigma_v, int | float) and math.isfinite(self.imm_sigma_v)
            and self.imm_sigma_v >= 0,
            "finite >= 0",
        )
        for name in ("miss_uses_gate_probability", "scale_caps", "startup_density",
                     "defer_tentative"):
            check(name, isinstance(getattr(self, name), bool), "a bool")
        check("n_scan", _is_int(self.n_scan) and 1 <= self.n_scan <= MAX_N_SCAN,
              f"an integer in [1, {MAX_N_SCAN}]")
        check("confirm_min_plots", _is_int(self.confirm_min_plots)
              and self.confirm_min_plots >= 1, "an integer >= 1")
        check("confirm_hits", _is_int(self.confirm_hits)
              and 0 <= self.confirm_hits <= self.n_scan + 1, "an integer in [0, n_scan + 1]")
        check("confirm_min_score", isinstance(self.confirm_min_score, int | float)
              and math.isfinite(self.confirm_min_score), "finite")
        for name in ("max_leaves_per_tree", "max_leaves", "max_trees", "max_gated_pairs",
                     "max_births_per_scan", "max_cluster_size", "milp_node_limit"):
            v = getattr(self, name)
            check(name, _is_int(v) and v >= 1, "an integer >= 1")
        check("history_scans", _is_int(self.history_scans)
              and 0 <= self.history_scans <= MAX_HISTORY_SCANS,
              f"an integer in [0, {MAX_HISTORY_SCANS}]")
        check("birth", self.birth in BIRTHS, f"one of {', '.join(BIRTHS)}")
        check("startup_density", not self.startup_density or self.birth == EVERY_PLOT,
              "False unless birth is 'every-plot'")
        check("birth_theta_deg", isinstance(self.birth_theta_deg, int | float)
              and 0 <= self.birth_theta_deg <= 180, "in [0, 180]")
        check("max_leaves", self.max_leaves > self.max_births_per_scan,
              "larger than max_births_per_scan")
        check("n_best", _is_int(self.n_best) and 1 <= self.n_best <= MAX_N_BEST,
              f"an integer in [1, {MAX_N_BEST}]")
        check("prune_probability", isinstance(self.prune_probability, int | float)
              and 0 <= self.prune_probability < 1, "in [0, 1)")
        check("merge_frames", _is_int(self.merge_frames)
              and 0 <= self.merge_frames <= self.n_scan + 1, "an integer in [0, n_scan + 1]")

    @property
    def models(self) -> CVModelSet | None:
        """The IMM's model set (quiet, manoeuvre), or ``None`` for a single CV model."""
        if self.imm_sigma_v <= 0:
            return None
        return CVModelSet((float(self.imm_sigma_v), float(self.sigma_v)), self.imm_mode_time)

    @property
    def motion(self) -> MotionModel:
        """The motion model these parameters name: the IMM (:attr:`models`) when
        ``imm_sigma_v > 0``, else a single constant-velocity model with ``sigma_v``."""
        models = self.models
        return ConstantVelocity(self.sigma_v) if models is None else models

    def to_json(self) -> str:
        """The configuration as a JSON string (exact round trip with :meth:`from_json`)."""
        return json.dumps(asdict(self), sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> MHTConfig:
        data: dict[str, Any] = json.loads(text)
        for name in REMOVED_FIELDS:  # saved by an older version; no longer has a meaning
            data.pop(name, None)
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"unknown MHTConfig fields: {unknown}")
        return cls(**data)


def _is_int(v: object) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)
