"""Hard caps: counting what they cut at each scan and telling the user.

Every stage that applies a cap (``max_gated_pairs``, ``max_births_per_scan``,
``max_leaves_per_tree``, ``max_leaves``, ``max_trees``, the solver's ``max_cluster_size``
and ``milp_node_limit``) adds to the scan's ``caps`` dict how many leaves, plots, trees or
clusters it cut; :class:`CapWarnings` logs them.
"""

from __future__ import annotations

import logging

from mhtrack.mht.hypothesis import GlobalHypothesis

#: The tracker's logger (the name users and the Monte-Carlo runner filter on).
logger = logging.getLogger("mhtrack.mht.tracker")


def solver_caps(hyp: GlobalHypothesis, caps: dict[str, int]) -> None:
    """Record the clusters solved greedily (too large) or stopped by the MILP node limit."""
    if hyp.n_greedy:
        caps["max_cluster_size"] = hyp.n_greedy
    if hyp.n_node_limited:
        caps["milp_node_limit"] = hyp.n_node_limited


class CapWarnings:
    """A warning the first time each cap acts; every scan's counts at DEBUG."""

    def __init__(self) -> None:
        self.warned: set[str] = set()

    def __call__(self, scan_index: int, caps: dict[str, int]) -> None:
        if not caps:
            return
        new = sorted(set(caps) - self.warned)
        if new:
            self.warned.update(new)
            logger.warning(
                "MHT scan %d: hard caps acted: %s (first time for %s; per-scan counts are "
                "in StepStats.caps)", scan_index, caps, ", ".join(new))
        else:
            logger.debug("MHT scan %d: hard caps acted: %s", scan_index, caps)
