"""Experiments: single tracking runs and Monte-Carlo studies."""

from mhtrack.experiments.pipeline import (
    TRACKERS,
    ScenarioRun,
    TrackingRun,
    config_with,
    make_tracker,
    run_scenario,
    track,
)

__all__ = [
    "TRACKERS",
    "ScenarioRun",
    "TrackingRun",
    "config_with",
    "make_tracker",
    "run_scenario",
    "track",
]
