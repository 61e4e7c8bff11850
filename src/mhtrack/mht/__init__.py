"""Track-oriented multiple hypothesis tracking (P1 §1.3): track trees of stacked leaves,
log-likelihood-ratio scores, clustering, an exact global hypothesis, N-scan pruning and
SPRT track management, with the motion model, the clutter estimator and the birth
process as parts passed in (the cycle's stages: :mod:`mhtrack.mht.tracker`)."""

from mhtrack.mht.births import Birth, BirthCandidates, EveryPlotBirth, InitiatorBirth
from mhtrack.mht.clustering import cluster_trees, plot_keys
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.gating import Gate, Gated, gate_sweep, gate_threshold
from mhtrack.mht.hypothesis import (
    GlobalHypothesis,
    best_hypothesis,
    solve_exact,
    solve_greedy,
    solve_milp,
)
from mhtrack.mht.pruning import (
    cap_leaves,
    cap_leaves_per_tree,
    cap_trees,
    n_scan_keep,
    score_drop_keep,
)
from mhtrack.mht.report import StepStats
from mhtrack.mht.scoring import birth_score, miss_increment, update_increment
from mhtrack.mht.sprt import SPRT, sprt_keep, sprt_thresholds, tentative_keep
from mhtrack.mht.tracker import MHTTracker
from mhtrack.mht.tree import Leaves

__all__ = [
    "SPRT",
    "Birth",
    "BirthCandidates",
    "EveryPlotBirth",
    "Gate",
    "Gated",
    "GlobalHypothesis",
    "InitiatorBirth",
    "Leaves",
    "MHTConfig",
    "MHTTracker",
    "StepStats",
    "best_hypothesis",
    "birth_score",
    "cap_leaves",
    "cap_leaves_per_tree",
    "cap_trees",
    "cluster_trees",
    "gate_sweep",
    "gate_threshold",
    "miss_increment",
    "n_scan_keep",
    "plot_keys",
    "score_drop_keep",
    "solve_exact",
    "solve_greedy",
    "solve_milp",
    "sprt_keep",
    "sprt_thresholds",
    "tentative_keep",
    "update_increment",
]
