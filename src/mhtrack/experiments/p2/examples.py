"""The single runs P2's example figures show (drawn by :mod:`mhtrack.reports.p2`): the
scan of Fig. 2 and the window of Figs. 12–15, both from run 0 of the study's seed."""

from __future__ import annotations

from mhtrack.experiments.initiation_runs import (
    ClusteringExample,
    InitiationExample,
    clustering_example,
    fuse,
    initiation_example,
    n_targets_seen,
)
from mhtrack.experiments.jobs import run_seed
from mhtrack.experiments.p2.constants import (
    ADAPTIVE_LABELS,
    FUSION_PARAMS,
    INITIATOR_PARAMS,
    LOGIC_PARAMS,
    THETA0,
)
from mhtrack.experiments.p2.jobs import p2_scenario
from mhtrack.scenario import simulate

#: P2's figure number of each initiator's panel, in the order of Figs. 12–15.
FIGURE_NUMBERS = {"modified-logic": 12, "logic": 13, "hough": 14, "modified-hough": 15}


def fig2_example(seed: int, settings: str = "best") -> ClusteringExample:
    """P2 Fig. 2: random vs adaptive K-means (with the fusion options of ``settings``) on
    the first scan of run 0 (no clutter) where random-start K-means gets ``k`` wrong (P2
    Fig. 2(a) shows such a failure); scan 0 if there is none."""
    sc = p2_scenario(clutter_rate=0.0)
    rs = run_seed(seed, 0, "words")
    number = 0
    for i, scan in enumerate(simulate(sc, rs).plots.scans()):
        if fuse(scan, "random", run_seed=rs).n_clusters != n_targets_seen(scan):
            number = i
            break
    return clustering_example(sc, seed, scan_number=number,
                              adaptive_params=FUSION_PARAMS[settings],
                              adaptive_label=ADAPTIVE_LABELS[settings])


def fig12_15_example(seed: int, settings: str = "best") -> InitiationExample:
    """P2 Figs. 12–15: the four initiators on the first fused window of run 0 at
    σr = 20 m, λ = 50, θ = 20°, with the fusion and initiator options of ``settings``
    (those of the study's jobs)."""
    return initiation_example(p2_scenario(), seed, theta_deg=THETA0,
                              methods=tuple(FIGURE_NUMBERS), **LOGIC_PARAMS,
                              fusion_params=FUSION_PARAMS[settings],
                              initiator_params=INITIATOR_PARAMS[settings])
