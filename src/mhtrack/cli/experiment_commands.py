"""``montecarlo``: many runs of several trackers on one scenario, summarised."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from mhtrack.cli.common import (
    InputProblem,
    echo_json,
    executor_kwargs,
    executor_options,
    exit_if_runs_failed,
    load_scenario_arg,
    scenario_options,
)
from mhtrack.cli.terminal import resume_on_interrupt, say
from mhtrack.cli.track_commands import config_changes, study_output_option, tracker_options


def _params_of(decorator: Callable[[Callable[..., Any]], Callable[..., Any]],
               drop: set[str]) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``decorator``'s click parameters except those named in ``drop``."""

    def apply(f: Callable[..., Any]) -> Callable[..., Any]:
        def probe() -> None: ...

        decorator(probe)
        params = [p for p in probe.__click_params__ if p.name not in drop]  # type: ignore[attr-defined]
        f.__dict__.setdefault("__click_params__", []).extend(params)
        return f

    return apply


def _trackers(ctx: click.Context, param: click.Parameter, value: str) -> tuple[str, ...]:
    from mhtrack.names import TRACKERS

    names = tuple(n.strip() for n in value.split(",") if n.strip())
    bad = [n for n in names if n not in TRACKERS]
    if bad or not names:
        raise click.BadParameter(
            f"unknown tracker(s) {', '.join(bad) or '(none given)'}; expected a comma-"
            f"separated list of {', '.join(TRACKERS)}")
    if len(set(names)) != len(names):
        raise click.BadParameter(f"repeated tracker in {value!r}")
    return names


def _run_kwargs(ctx: click.Context, param: click.Parameter, value: tuple[str, ...]
                ) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in value:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise click.BadParameter(f"expected KEY=VALUE, got {item!r}")
        try:
            out[key.strip()] = json.loads(text)
        except ValueError:
            out[key.strip()] = text
    return out


@click.command()
@_params_of(scenario_options, drop={"seed"})
@click.option("--trackers", default="mht,mht-gmm,mht-agmm", show_default=True,
              callback=_trackers, help="Comma-separated trackers to compare.")
@click.option("--runs", type=click.IntRange(min=1, max=1_000_000), default=10,
              show_default=True, help="Runs per tracker (at most 10⁶: every run is one file "
              "that the summary reads back).")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Base seed; run i simulates with a seed derived from (SEED, i) only, the "
              "same for every tracker.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Study directory (runs/, montecarlo.json, summary.md, "
              "ospa_cardinality.png); an existing one with the same parameters is resumed.")
@executor_options
@_params_of(tracker_options("--tracker-pd"), drop={"tracker"})
@click.option("--cutoff", type=click.FloatRange(min=0, min_open=True), default=500.0,
              show_default=True, help="OSPA/GOSPA cut-off c (m).")
@click.option("--order", type=click.FloatRange(min=1), default=2.0, show_default=True,
              help="OSPA/GOSPA order p.")
@study_output_option
@click.option("--run-kwarg", "run_kwarg", multiple=True, callback=_run_kwargs,
              metavar="KEY=VALUE", help="Extra keyword of run_scenario (VALUE read as JSON, "
              "else as text); repeatable.")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object keyed by tracker (means, std, per-scan curves).")
def montecarlo(scenario: str, clutter: str | None, clutter_rate: float | None,
               pd: float | None, scans: int | None, trackers: tuple[str, ...], runs: int,
               seed: int, out: Path, workers: int | None, dask_scheduler: str | None,
               tracker_pd: float | None, meas_sigma: float | None,
               accel_sigma: float | None, imm_accel_sigma: float | None,
               clutter_density: float | None,
               birth_density: float | None, nscan: int | None, cutoff: float, order: float,
               output: str, run_kwarg: dict[str, Any], as_json: bool) -> None:
    """Monte-Carlo study: RUNS simulations of SCENARIO, each tracked by every tracker.

    Every finished run is written at once to OUT/runs/<tracker>/run-<i>.parquet; rerunning
    the same command resumes. Prints mean ± std per tracker and metric (also in
    OUT/summary.md) and draws OUT/ospa_cardinality.png. A failed run is recorded in
    OUT/runs/<tracker>/run-<i>.error.txt; the exit status is then 1.
    """
    from mhtrack.experiments.montecarlo import (
        MonteCarloSpec,
        SpecMismatchError,
        run_montecarlo,
    )
    from mhtrack.reports.montecarlo import summary_markdown, write_montecarlo_report

    run_on = executor_kwargs(workers, dask_scheduler)
    sc = load_scenario_arg(scenario, clutter, clutter_rate, pd, scans)
    tracker_pd = tracker_pd if tracker_pd is not None else pd
    config = config_changes(tracker_pd, meas_sigma, accel_sigma, birth_density, nscan,
                            imm_accel_sigma)
    kwargs: dict[str, Any] = {"cutoff": cutoff, "order": order, "output": output}
    if clutter_density is not None:
        kwargs["clutter_density"] = clutter_density
    kwargs.update(run_kwarg)
    try:
        spec = MonteCarloSpec(sc, trackers, runs, seed, config=config, run_kwargs=kwargs)
        with resume_on_interrupt("montecarlo", out):
            result = run_montecarlo(spec, out, **run_on)
    except (SpecMismatchError, ValueError) as e:
        raise InputProblem(str(e)) from None
    write_montecarlo_report(result)
    if as_json:
        echo_json(result.summary())
    else:
        say(summary_markdown(result), nl=False)
        say(f"{result.computed} runs computed, {result.skipped} already done; "
            f"wrote {out}/ (runs/, montecarlo.json, summary.md, ospa_cardinality.png)")
    capped = {t: n for t, n in result.runs_with_caps().items() if n}
    if capped:
        listed = ", ".join(f"{t}: {n} of {len(result.records[t])} runs" for t, n in capped.items())
        say(f"mhtrack montecarlo: hard caps of the MHT acted ({listed}); per-run "
            f"counts in the 'caps' column of {out}/runs/", err=True)
    exit_if_runs_failed("montecarlo", result)


COMMANDS = [montecarlo]
