"""Experiments: single tracking runs and Monte-Carlo studies."""

from mhtrack.experiments.montecarlo import (
    MonteCarloResult,
    MonteCarloSpec,
    SpecMismatchError,
    load_results,
    run_job,
    run_montecarlo,
    run_seed,
)
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
    "MonteCarloResult",
    "MonteCarloSpec",
    "ScenarioRun",
    "SpecMismatchError",
    "TrackingRun",
    "config_with",
    "load_results",
    "make_tracker",
    "run_job",
    "run_montecarlo",
    "run_scenario",
    "run_seed",
    "track",
]
