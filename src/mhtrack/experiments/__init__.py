"""Experiments: single tracking runs (:mod:`.pipeline`), Monte-Carlo studies
(:mod:`.montecarlo`), the P1 and P2 reproductions (:mod:`.p1`, :mod:`.p2`), the
multi-radar initiation runs (:mod:`.initiation_runs`), all on one job runner
(:mod:`.jobs`). They compute and store results; :mod:`mhtrack.reports` writes the text
and figures."""

from mhtrack.experiments.montecarlo import (
    MonteCarloResult,
    MonteCarloSpec,
    SpecMismatchError,
    load_results,
    run_job,
    run_montecarlo,
)
from mhtrack.experiments.pipeline import ScenarioRun, TrackingRun, run_scenario, track

__all__ = [
    "MonteCarloResult",
    "MonteCarloSpec",
    "ScenarioRun",
    "SpecMismatchError",
    "TrackingRun",
    "load_results",
    "run_job",
    "run_montecarlo",
    "run_scenario",
    "track",
]
