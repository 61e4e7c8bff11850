"""``reproduce``: rerun a paper's experiment and compare with its printed numbers."""

from __future__ import annotations

import sys
from pathlib import Path

import click


@click.group()
def reproduce() -> None:
    """Reproduce a paper's experiment: its table and figures, beside the paper's numbers."""


@reproduce.command("p1")
@click.option("--runs", type=click.IntRange(min=1), default=10, show_default=True,
              help="Monte-Carlo runs per tracker.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Output directory (montecarlo/, table3.md, table3.json, report.md, "
              "fig2–fig6 PNG); an existing study with the same parameters is resumed.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Base seed; run i simulates with a seed derived from (SEED, i) only.")
@click.option("--workers", type=click.IntRange(min=1), default=None,
              help="Local worker processes [number of CPUs]; 1 runs in this process.")
@click.option("--dask-scheduler", default=None, metavar="ADDRESS",
              help="Run the jobs on this Dask scheduler (e.g. tcp://host:8786) instead.")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar over jobs on stderr [when stderr is a terminal].")
def p1(runs: int, out: Path, seed: int, workers: int | None, dask_scheduler: str | None,
       progress: bool | None) -> None:
    """P1 §3: Monte-Carlo study of `crossing` with mht, mht-gmm and mht-agmm.

    Writes OUT/montecarlo/ (the runs; rerunning resumes), OUT/table3.md (our Table 3,
    mean ± std over RUNS runs, beside P1's numbers), OUT/report.md (settings, comparison,
    figures) and P1's Figs. 2–6 as OUT/fig2_truth.png … OUT/fig6_cardinality.png. Prints
    the table. Exit status 1 if any run failed (after everything was written).
    """
    from mhtrack.experiments.montecarlo import SpecMismatchError
    from mhtrack.experiments.reproduce_p1 import reproduce_p1

    if workers is not None and dask_scheduler is not None:
        raise click.UsageError("give --workers or --dask-scheduler, not both")
    try:
        repro = reproduce_p1(
            out, runs, seed, executor="dask" if dask_scheduler else "local",
            workers=workers, scheduler=dask_scheduler,
            progress=sys.stderr.isatty() if progress is None else progress)
    except (SpecMismatchError, ValueError) as e:
        raise click.ClickException(str(e)) from None
    res = repro.result
    click.echo(repro.table_md)
    click.echo(f"{res.computed} runs computed, {res.skipped} already done.")
    click.echo("wrote:")
    for p in repro.paths:
        click.echo(f"  {p}{'/' if p.is_dir() else ''}")
    failed = [(t, i) for t, f in res.failures.items() for i in sorted(f)]
    if failed or res.missing:
        shown = ", ".join(f"{t} run {i}" for t, i in failed[:10])
        more = f" and {len(failed) - 10} more" if len(failed) > 10 else ""
        click.echo(f"mhtrack reproduce p1: {len(failed)} run(s) failed ({shown}{more}); "
                   f"tracebacks in {res.out_dir}/runs/<tracker>/run-<i>.error.txt", err=True)
        click.get_current_context().exit(1)


COMMANDS = [reproduce]
