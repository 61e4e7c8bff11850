"""Track-oriented multiple hypothesis tracking (P1 §1.3): track trees of stacked leaves,
log-likelihood-ratio scores, clustering, an exact global hypothesis, N-scan pruning and
SPRT track management, with the clutter intensity from a pluggable estimator."""

from mhtrack.mht.clustering import cluster_trees, plot_keys
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.hypothesis import (
    GlobalHypothesis,
    best_hypothesis,
    brute_force_best_hypothesis,
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
    sprt_keep,
)
from mhtrack.mht.scoring import birth_score, miss_increment, sprt_thresholds, update_increment
from mhtrack.mht.tracker import MHTTracker, StepStats
from mhtrack.mht.tree import Leaves

__all__ = [
    "GlobalHypothesis",
    "Leaves",
    "MHTConfig",
    "MHTTracker",
    "StepStats",
    "best_hypothesis",
    "birth_score",
    "brute_force_best_hypothesis",
    "cap_leaves",
    "cap_leaves_per_tree",
    "cap_trees",
    "cluster_trees",
    "miss_increment",
    "n_scan_keep",
    "plot_keys",
    "score_drop_keep",
    "solve_exact",
    "solve_greedy",
    "solve_milp",
    "sprt_keep",
    "sprt_thresholds",
    "update_increment",
]
