"""Options and helpers shared by several commands."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click


class InputProblem(click.ClickException):
    """A user's input is wrong: one line on stderr, exit status 2 (as a usage error)."""

    exit_code = 2


def scenario_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``SCENARIO`` (preset name or TOML file) and the common overrides."""
    for opt in reversed(
        [
            click.argument("scenario"),
            click.option("--seed", type=int, default=0, show_default=True,
                         help="Random seed; same seed, same output."),
            click.option("--clutter", type=click.Choice(["uniform", "gmm"]), default=None,
                         help="Replace the scenario's clutter density."),
            click.option("--clutter-rate", type=click.FloatRange(min=0), default=None,
                         help="Mean clutter plots per scan (per sensor)."),
            click.option("--pd", type=click.FloatRange(0, 1), default=None,
                         help="Detection probability of every sensor."),
            click.option("--scans", type=click.IntRange(min=1), default=None,
                         help="Number of scans to simulate."),
        ]
    ):
        f = opt(f)
    return f


def load_scenario_arg(
    scenario: str, clutter: str | None, clutter_rate: float | None, pd: float | None,
    scans: int | None,
) -> Any:
    """A preset by name, or a scenario TOML file, with the command-line overrides."""
    from mhtrack.scenario import PRESETS, apply_overrides, load_scenario, preset

    overrides = {"clutter": clutter, "clutter_rate": clutter_rate, "pd": pd, "scans": scans}
    overrides = {k: v for k, v in overrides.items() if v is not None}
    if scenario in PRESETS:
        return preset(scenario, **overrides)
    path = Path(scenario)
    if path.suffix.lower() == ".toml" or path.exists():
        from mhtrack.io.paths import check_input_file

        if not path.exists():
            raise click.BadParameter(f"no such scenario file: {path}", param_hint="SCENARIO")
        check_input_file(path)
        return apply_overrides(load_scenario(path), **overrides)
    names = ", ".join(sorted(PRESETS))
    raise click.BadParameter(
        f"unknown scenario {scenario!r}: give a preset ({names}) or a .toml file",
        param_hint="SCENARIO",
    )


def echo_json(obj: Any) -> None:
    """Print one JSON object (NaN/inf become null so any JSON parser reads it)."""
    from mhtrack.io.jsonsafe import dumps

    click.echo(dumps(obj))


def table_path(directory: Path, stem: str) -> Path | None:
    """``DIR/stem.csv`` or ``DIR/stem.parquet``, whichever exists."""
    for ext in (".csv", ".parquet"):
        p = directory / f"{stem}{ext}"
        if p.is_file():
            return p
    return None


def executor_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--workers`` / ``--dask-scheduler`` / ``--progress`` of the Monte-Carlo commands."""
    for opt in reversed(
        [
            click.option("--workers", type=click.IntRange(min=1), default=None,
                         help="Local worker processes [number of CPUs]; 1 runs in this "
                         "process."),
            click.option("--dask-scheduler", default=None, metavar="ADDRESS",
                         help="Run the jobs on this Dask scheduler (e.g. tcp://host:8786) "
                         "instead."),
            click.option("--progress/--no-progress", default=None,
                         help="Progress bar over jobs on stderr [when stderr is a "
                         "terminal]."),
        ]
    ):
        f = opt(f)
    return f


def executor_kwargs(workers: int | None, dask_scheduler: str | None,
                    progress: bool | None) -> dict[str, Any]:
    """The ``executor``, ``workers``, ``scheduler`` and ``progress`` keywords of the
    experiment runners, from :func:`executor_options`' values."""
    if workers is not None and dask_scheduler is not None:
        raise click.UsageError("give --workers or --dask-scheduler, not both")
    return {
        "executor": "dask" if dask_scheduler else "local",
        "workers": workers,
        "scheduler": dask_scheduler,
        "progress": sys.stderr.isatty() if progress is None else progress,
    }


def exit_if_runs_failed(command: str, result: Any) -> None:
    """After a Monte-Carlo study (:class:`~mhtrack.experiments.MonteCarloResult`): name the
    failed runs on stderr and exit with status 1, if any failed or are missing."""
    failed = [(t, i) for t, f in result.failures.items() for i in sorted(f)]
    if failed or result.missing:
        shown = ", ".join(f"{t} run {i}" for t, i in failed[:10])
        more = f" and {len(failed) - 10} more" if len(failed) > 10 else ""
        click.echo(f"mhtrack {command}: {len(failed)} run(s) failed ({shown}{more}); "
                   f"tracebacks in {result.out_dir}/runs/<tracker>/run-<i>.error.txt",
                   err=True)
        click.get_current_context().exit(1)
