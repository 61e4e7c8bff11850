"""The figures of one run of ``mhtrack cluster`` and ``mhtrack initiate`` (``--figure``):
the data from :mod:`mhtrack.experiments.initiation_runs`, drawn by
:mod:`mhtrack.plotting.initiation`."""

from __future__ import annotations

from typing import Any

from matplotlib.figure import Figure

from mhtrack.experiments.initiation_runs import clustering_example, initiation_example
from mhtrack.scenario import Scenario


def clustering_figure_for(scenario: Scenario, seed: int, *, scan_number: int = 0) -> Figure:
    """Random vs adaptive K-means on one scan of the first run of ``seed``."""
    from mhtrack.plotting.initiation import clustering_figure

    ex = clustering_example(scenario, seed, scan_number=scan_number)
    return clustering_figure(ex.scan, ex.fused, ex.truth_xy,
                             title=f"{scenario.name}, scan {ex.scan.index}")


def initiation_figure_for(scenario: Scenario, seed: int, *, fusion: str = "adaptive-kmeans",
                          theta_deg: float = 20.0, window_number: int = 0,
                          **settings: Any) -> Figure:
    """Every initiator on one window of the first run of ``seed``, with the CLI's settings
    (``gate_radius``, ``v_min``, ``v_max``; Hough accumulators over the scenario's region)."""
    from mhtrack.plotting.initiation import initiation_figure

    ex = initiation_example(scenario, seed, fusion=fusion, theta_deg=theta_deg,
                            window_number=window_number, **settings)
    s = ex.fused.scans
    return initiation_figure(ex.raw, ex.fused, ex.tracks, ex.truth_xy,
                             title=f"{scenario.name}, scans {s[0]}–{s[-1]}, fusion {fusion}, "
                             f"θ = {theta_deg:g}°")
