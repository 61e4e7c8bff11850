"""The P1 §3 study: the Monte-Carlo study of ``crossing`` with P1's three trackers, our
Table 3 numbers beside P1's, and run 0 recomputed for Figs. 3–4.

:func:`reproduce_p1` runs (or resumes) the study through
:func:`~mhtrack.experiments.montecarlo.run_montecarlo` into ``DIR/montecarlo/`` and returns
a :class:`P1Reproduction`; :func:`mhtrack.reports.p1.write_p1_report` writes Table 3, the
report and Figs. 2–6 from it.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mhtrack.experiments.jobs import run_seed
from mhtrack.experiments.montecarlo import MonteCarloResult, MonteCarloSpec, run_montecarlo
from mhtrack.experiments.p1.constants import (
    MC_DIR,
    P1_TRACKERS,
    PAPER_TABLE3,
    RUN_KWARGS,
    TABLE3_METRICS,
)
from mhtrack.scenario import Scenario


@dataclass
class P1Reproduction:
    """What :func:`reproduce_p1` computed: the Monte-Carlo ``result``, the Table 3 numbers
    (tracker → metric → ``mean``/``std``/``paper``), and run 0 recomputed with the
    runner's seed (``run0[tracker]`` its ScenarioRun, ``None`` if it failed; ``simulation``
    its simulated scene)."""

    out_dir: Path
    result: MonteCarloResult
    table: dict[str, dict[str, dict[str, float]]]
    run0: dict[str, Any] = field(default_factory=dict)
    run0_seed: int = 0
    simulation: Any = None


def _num(v: Any) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return math.nan
    return f


def table3_numbers(summary: Mapping[str, Mapping[str, Any]],
                   trackers: Sequence[str] = P1_TRACKERS) -> dict[str, dict[str, dict[str, float]]]:
    """``{tracker: {metric: {"mean", "std", "paper"}}}`` from a Monte-Carlo summary; the
    paper's value is NaN where P1 gives none (OSPA)."""
    out: dict[str, dict[str, dict[str, float]]] = {}
    for t in trackers:
        s = summary.get(t, {})
        std = s.get("std", {})
        out[t] = {
            m.key: {"mean": _num(s.get(m.key)), "std": _num(std.get(m.key)),
                    "paper": _num(PAPER_TABLE3.get(t, {}).get(m.key))}
            for m in TABLE3_METRICS
        }
    return out


def p1_scenario() -> Scenario:
    """The scenario of P1 §3: the ``crossing`` preset, unchanged."""
    from mhtrack.scenario import preset

    return preset("crossing")


def p1_spec(runs: int, seed: int = 0, scenario: Scenario | None = None) -> MonteCarloSpec:
    """The study: ``crossing`` (or ``scenario``), P1's three trackers, default configuration
    (P1's parameters), :data:`~mhtrack.experiments.p1.constants.RUN_KWARGS`."""
    sc = p1_scenario() if scenario is None else scenario
    return MonteCarloSpec(sc, P1_TRACKERS, runs=runs, seed=seed, config={},
                          run_kwargs=dict(RUN_KWARGS))


def reproduce_p1(
    out_dir: str | os.PathLike[str],
    runs: int = 10,
    seed: int = 0,
    *,
    scenario: Scenario | None = None,
    executor: str = "local",
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
) -> P1Reproduction:
    """Run (or resume) the P1 study into ``out_dir/montecarlo/``, compute Table 3's
    numbers and recompute run 0 of each tracker (module docstring). ``scenario`` replaces
    the ``crossing`` preset (tests use a shortened one). Raises
    :class:`~mhtrack.experiments.montecarlo.SpecMismatchError` if ``out_dir/montecarlo``
    holds another study."""
    from mhtrack.build import config_with
    from mhtrack.experiments.pipeline import run_scenario

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    spec = p1_spec(runs, seed, scenario)
    result = run_montecarlo(spec, out_dir / MC_DIR, executor=executor, workers=workers,
                            scheduler=scheduler, progress=progress)

    # run 0, recomputed with the runner's seed (the one stored in its records when present)
    seed0 = run_seed(spec.seed, 0, "spawn")
    for t in spec.trackers:
        for r in result.records.get(t, []):
            if r["run"] == 0:
                seed0 = int(r["seed"])
                break
    sc = Scenario.from_dict(spec.scenario)
    config = config_with(**spec.config) if spec.config else None
    run0: dict[str, Any] = {}
    sim = None
    for t in spec.trackers:
        try:
            run0[t] = run_scenario(sc, seed0, t, config, **spec.run_kwargs)
            sim = run0[t].simulation
        except Exception:  # the runner recorded the failure; draw an empty panel
            run0[t] = None
    if sim is None:
        from mhtrack.scenario import simulate

        sim = simulate(sc, seed=seed0)
    table = table3_numbers(result.summary(), spec.trackers)
    return P1Reproduction(out_dir, result, table, run0, seed0, sim)
