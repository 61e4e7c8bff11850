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
from mhtrack.experiments.montecarlo.spec import SPEC_FILE
from mhtrack.experiments.p1.constants import (
    DEFAULT_SETTINGS,
    MC_DIR,
    P1_TRACKERS,
    PAPER_TABLE3,
    TABLE3_METRICS,
    TRACKER_SETTINGS,
    TrackerSettings,
    settings_file,
)
from mhtrack.experiments.p1.paired import p1_paired
from mhtrack.metrics.paired import PairedComparison
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
    settings: TrackerSettings = TRACKER_SETTINGS[DEFAULT_SETTINGS]
    #: the other settings' studies found in ``out_dir`` (same scenario and seed)
    others: dict[str, MonteCarloResult] = field(default_factory=dict)
    #: their Table 3 numbers
    other_tables: dict[str, dict[str, dict[str, dict[str, float]]]] = field(
        default_factory=dict)
    #: paired comparisons: between trackers, then each tracker against the other settings
    paired: list[PairedComparison] = field(default_factory=list)


def _num(v: Any) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return math.nan
    return f


def table3_numbers(summary: Mapping[str, Mapping[str, Any]],
                   trackers: Sequence[str] = P1_TRACKERS,
                   records: Mapping[str, Sequence[Mapping[str, Any]]] | None = None,
                   ) -> dict[str, dict[str, dict[str, float]]]:
    """``{tracker: {metric: {"mean", "std", "paper", "ci_low", "ci_high"}}}`` from a
    Monte-Carlo summary; the paper's value is NaN where P1 gives none (OSPA);
    ``ci_low``/``ci_high`` the 95 % t interval of the mean over the runs' values
    (:func:`mhtrack.metrics.paired.t_interval`; NaN without ``records`` or with < 2 runs)."""
    from mhtrack.metrics.paired import t_interval

    out: dict[str, dict[str, dict[str, float]]] = {}
    for t in trackers:
        s = summary.get(t, {})
        std = s.get("std", {})
        recs = (records or {}).get(t, [])
        out[t] = {}
        for m in TABLE3_METRICS:
            lo, hi = t_interval([_num(r.get(m.key)) for r in recs]) if recs else (
                math.nan, math.nan)
            out[t][m.key] = {"mean": _num(s.get(m.key)), "std": _num(std.get(m.key)),
                             "paper": _num(PAPER_TABLE3.get(t, {}).get(m.key)),
                             "ci_low": lo, "ci_high": hi}
    return out


def p1_scenario() -> Scenario:
    """The scenario of P1 §3: the ``crossing`` preset, unchanged."""
    from mhtrack.scenario import preset

    return preset("crossing")


def p1_spec(runs: int, seed: int = 0, scenario: Scenario | None = None,
            settings: str = DEFAULT_SETTINGS) -> MonteCarloSpec:
    """The study: ``crossing`` (or ``scenario``), P1's three trackers, the configuration
    and run keywords of ``settings`` (:data:`~mhtrack.experiments.p1.constants.
    TRACKER_SETTINGS`; ``best``: the defaults and ``RUN_KWARGS``)."""
    sc = p1_scenario() if scenario is None else scenario
    st = settings_of(settings)
    return MonteCarloSpec(sc, P1_TRACKERS, runs=runs, seed=seed, config=dict(st.config),
                          run_kwargs=dict(st.run_kwargs))


def settings_of(name: str) -> TrackerSettings:
    """The :class:`TrackerSettings` called ``name``; ``ValueError`` for another name."""
    if name not in TRACKER_SETTINGS:
        raise ValueError(f"--tracker-settings: unknown {name!r} "
                         f"(expected {' or '.join(TRACKER_SETTINGS)})")
    return TRACKER_SETTINGS[name]


def _other_studies(out_dir: Path, spec: MonteCarloSpec, settings: TrackerSettings
                   ) -> dict[str, MonteCarloResult]:
    """The studies of the other settings already in ``out_dir`` with the same scenario and
    seed (read, never run)."""
    from mhtrack.experiments.montecarlo import load_results

    found: dict[str, MonteCarloResult] = {}
    for name, st in TRACKER_SETTINGS.items():
        if name == settings.name:
            continue
        d = out_dir / settings_file(MC_DIR, st)
        if not (d / SPEC_FILE).is_file():
            continue
        try:
            res = load_results(d)
        except (OSError, ValueError):
            continue
        if res.spec.scenario == spec.scenario and res.spec.seed == spec.seed:
            found[name] = res
    return found


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
    settings: str = DEFAULT_SETTINGS,
) -> P1Reproduction:
    """Run (or resume) the P1 study into ``out_dir/montecarlo/``, compute Table 3's
    numbers and recompute run 0 of each tracker (module docstring). ``scenario`` replaces
    the ``crossing`` preset (tests use a shortened one). ``settings``: ``best`` (ours,
    into ``out_dir/montecarlo/``) or ``paper`` (P1's tracker, into
    ``out_dir/montecarlo-paper/``); a study of the other settings already in ``out_dir``
    is read for the side-by-side table. Raises
    :class:`~mhtrack.experiments.montecarlo.SpecMismatchError` if ``out_dir/montecarlo``
    holds another study."""
    from mhtrack.build import config_with, default_config
    from mhtrack.experiments.pipeline import run_scenario

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    st = settings_of(settings)
    spec = p1_spec(runs, seed, scenario, settings)
    result = run_montecarlo(spec, out_dir / settings_file(MC_DIR, st), executor=executor,
                            workers=workers,
                            scheduler=scheduler, progress=progress)

    # run 0, recomputed with the runner's seed (the one stored in its records when present)
    seed0 = run_seed(spec.seed, 0, "spawn")
    for t in spec.trackers:
        for r in result.records.get(t, []):
            if r["run"] == 0:
                seed0 = int(r["seed"])
                break
    sc = Scenario.from_dict(spec.scenario)
    config = config_with(default_config(sc), **spec.config)  # as the jobs build it
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
    table = table3_numbers(result.summary(), spec.trackers, result.records)
    others = _other_studies(out_dir, spec, st)
    other_tables = {k: table3_numbers(r.summary(), spec.trackers, r.records)
                    for k, r in others.items()}
    paired = p1_paired(result, st, others)
    return P1Reproduction(out_dir, result, table, run0, seed0, sim, st, others,
                          other_tables, paired)
