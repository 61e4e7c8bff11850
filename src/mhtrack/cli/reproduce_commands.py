"""``reproduce``: rerun a paper's experiment and compare with its printed numbers."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from mhtrack.cli.common import InputProblem, executor_kwargs, executor_options, exit_if_runs_failed
from mhtrack.cli.terminal import resume_on_interrupt, say


@click.group()
def reproduce() -> None:
    """Reproduce a paper's experiment: its table and figures, beside the paper's numbers."""


@reproduce.command("p1")
@click.option("--runs", type=click.IntRange(min=1, max=1_000_000), default=10,
              show_default=True, help="Monte-Carlo runs per tracker (at most 10⁶).")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Output directory (montecarlo/, table3.md, table3.json, report.md, "
              "fig2–fig6 PNG); an existing study with the same parameters is resumed.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Base seed; run i simulates with a seed derived from (SEED, i) only.")
@click.option("--tracker-settings", "tracker_settings", type=click.Choice(["paper", "best"]),
              default="best", show_default=True,
              help="paper: P1's tracker (one constant-velocity model, online output, "
              "P1's clutter-estimator steps only); best: ours (two-model IMM, history "
              "output, our estimator additions).")
@executor_options
def p1(runs: int, out: Path, seed: int, tracker_settings: str, workers: int | None,
       dask_scheduler: str | None) -> None:
    """P1 §3: Monte-Carlo study of `crossing` with mht, mht-gmm and mht-agmm.

    Writes OUT/montecarlo/ (the runs; rerunning resumes), OUT/table3.md (our Table 3,
    mean ± std over RUNS runs, beside P1's numbers, and the paired comparisons),
    OUT/table3.json, OUT/report.md (settings, comparison, figures) and P1's Figs. 2–6 as
    OUT/fig2_truth.png … OUT/fig6_cardinality.png. With --tracker-settings paper the
    files are OUT/montecarlo-paper/, OUT/table3-paper.md, OUT/report-paper.md, … and a
    study of the other settings in OUT is shown beside it. Prints the table. Exit status
    1 if any run failed (after everything was written).
    """
    from mhtrack.experiments.montecarlo import SpecMismatchError
    from mhtrack.experiments.p1 import reproduce_p1
    from mhtrack.reports.p1 import write_p1_report

    run_on = executor_kwargs(workers, dask_scheduler)
    try:
        with resume_on_interrupt("reproduce p1", out):
            repro = reproduce_p1(out, runs, seed, settings=tracker_settings, **run_on)
    except (SpecMismatchError, ValueError) as e:
        raise InputProblem(str(e)) from None
    report = write_p1_report(repro)
    res = repro.result
    say(report.table_md)
    say(f"{res.computed} runs computed, {res.skipped} already done.")
    _wrote(report.paths)
    exit_if_runs_failed("reproduce p1", res)


@reproduce.command("p2")
@click.option("--runs", type=click.IntRange(min=1), default=10, show_default=True,
              help="Monte-Carlo runs per grid point (P2: 1000).")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Output directory (jobs/, results.json, tables.md, report.md, "
              "fig2/fig3/fig4/fig12_15 PNG); finished jobs in OUT/jobs are skipped.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Base seed; run i simulates with a seed derived from (SEED, i) only.")
@click.option("--tracker-settings", "settings", type=click.Choice(["best", "paper"]),
              default="best", show_default=True,
              help="paper: P2's steps only (adaptive K-means without our repair, merge and "
              "gate; modified Hough with the acceleration constraint); best: ours.")
@click.option("--clutter-per", type=click.Choice(["radar", "scan"]), default="radar",
              show_default=True,
              help="Read λ as clutter plots per radar per scan, or per scan over all radars.")
@executor_options
def p2(runs: int, out: Path, seed: int, settings: str, clutter_per: str,
       workers: int | None, dask_scheduler: str | None) -> None:
    """P2 (Gong, Dai & Ma 2013) on `multiradar`: Figs. 2, 3, 4, 12–15 and Tables 1–2.

    Fig. 3: p_true of the modified 3/4 logic against θ ∈ {0°, 10°, …, 180°} for
    σr ∈ {20, …, 60} m at λ = 50; Fig. 4: p_false against θ for λ ∈ {50, …, 250} at
    σr = 20 m (each run simulated once, every θ evaluated on the same windows);
    Fig. 2: adaptive vs random-start K-means; Figs. 12–15: the four initiators on one
    window; Tables 1–2: run times beside P2's. Writes OUT/results.json, OUT/tables.md,
    OUT/report.md and the figures. Exit status 1 if any job failed.
    """
    from mhtrack.experiments.p2 import reproduce_p2
    from mhtrack.reports.p2 import write_p2_report

    run_on = executor_kwargs(workers, dask_scheduler)
    try:
        with resume_on_interrupt("reproduce p2", out):
            repro = reproduce_p2(out, runs, seed, settings=settings, clutter_per=clutter_per,
                                 **run_on)
    except ValueError as e:
        raise InputProblem(str(e)) from None
    paths = write_p2_report(repro)
    say((repro.out_dir / "tables.md").read_text(encoding="utf-8"))
    say(f"{repro.computed} jobs computed, {repro.skipped} already done "
        f"({repro.wall_seconds:.1f} s).")
    _wrote(paths)
    _exit_if_jobs_failed("p2", repro.errors, f"{repro.out_dir}/jobs/<name>.error.txt")


@reproduce.command("clutter-shift")
@click.option("--runs", type=click.IntRange(min=1), default=50, show_default=True,
              help="Paired runs (every method on the same simulated plots in run i).")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Output directory (jobs/, results.json, report.md, clutter_error.png); "
              "finished jobs in OUT/jobs are skipped.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Base seed; run i simulates with a seed derived from (SEED, i) only.")
@click.option("--ablation-runs", type=click.IntRange(min=0), default=0, show_default=True,
              help="Also run each clutter estimator alone, one design choice switched at a "
              "time, on the first N runs, and explain the AGMM–GMM verdict from it in the "
              "report (kept in OUT/ablation.json).")
@click.option("--method", "methods", multiple=True, metavar="NAME",
              help="A method to run (known, uniform or a clutter estimator's name, e.g. "
              "fgmm, map; repeat) [known, uniform, gmm, agmm].")
@click.option("--preset", default="crossing-changing", show_default=True, metavar="NAME",
              help="The scenario preset to track (P1's crossing: crossing).")
@executor_options
def clutter_shift(runs: int, out: Path, seed: int, ablation_runs: int,
                  methods: tuple[str, ...], preset: str, workers: int | None,
                  dask_scheduler: str | None) -> None:
    """Known κ, uniform κ̂, GMM and AGMM on `crossing-changing`, a clutter that changes.

    Every method tracks the same RUNS simulations; the report compares them run by run
    (mean difference with its 95 % interval, sign and Wilcoxon tests, verdict) in the
    tracking metrics and in the clutter-estimate error ∫|κ̂ − κ|. Writes OUT/results.json,
    OUT/report.md and OUT/clutter_error.png. Exit status 1 if any job failed.
    """
    from mhtrack.experiments import clutter_shift as cs
    from mhtrack.reports.clutter_shift import write_clutter_shift_report

    run_on = executor_kwargs(workers, dask_scheduler)
    try:
        from mhtrack.scenario import preset as load_preset

        scenario = cs.default_scenario() if preset == cs.PRESET else load_preset(preset)
        with resume_on_interrupt("reproduce clutter-shift", out):
            study = cs.clutter_shift(out, runs, seed, scenario=scenario,
                                     methods=methods or tuple(cs.METHODS), **run_on)
    except ValueError as e:
        raise InputProblem(str(e)) from None
    ablation = None
    if ablation_runs:
        from mhtrack.experiments.clutter_shift_ablation import cached_ablation

        ablation = cached_ablation(out, scenario, ablation_runs, seed)
    rep = write_clutter_shift_report(study, scenario, ablation)
    for c in study.paired:
        if c.b == "gmm" and c.a != "known":
            say(f"* {c.sentence}")
    say(f"{study.computed} jobs computed, {study.skipped} already done.")
    _wrote(rep.paths)
    _exit_if_jobs_failed("clutter-shift", study.errors, f"{out}/jobs/")


@reproduce.command("clutter-scenes")
@click.option("--runs", type=click.IntRange(min=1), default=50, show_default=True,
              help="Paired runs per scene (every method on the same simulated plots in run i).")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Output directory (jobs/, results.json, report.md); finished jobs in "
              "OUT/jobs are skipped.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Base seed; run i simulates with a seed derived from (SEED, i) only.")
@click.option("--scene", "scenes", multiple=True, metavar="NAME",
              help="A clutter scene to run (weather, coastal, burst, storm; repeat) "
              "[all].")
@click.option("--method", "methods", multiple=True, metavar="NAME",
              help="A method to run (known, uniform or a clutter estimator's name; repeat) "
              "[all].")
@click.option("--scans", type=click.IntRange(min=2), default=None,
              help="Shorten the radars-clutter scenario to this many scans (1 s each).")
@click.option("--html", "html", is_flag=True,
              help="Also write OUT/report.html (needs Plotly: the [report] extra).")
@executor_options
def clutter_scenes(runs: int, out: Path, seed: int, scenes: tuple[str, ...],
                   methods: tuple[str, ...], scans: int | None, html: bool,
                   workers: int | None, dask_scheduler: str | None) -> None:
    """Every clutter estimator on rotating radars in changing clutter scenes.

    The radars-clutter scenario with each clutter scene (weather cells drifting and
    growing, ground and sea clutter, a burst; docs/clutter.md): known κ (oracle), uniform
    κ̂, and every registered estimator, RUNS paired runs per scene; the report compares
    them run by run (95 % interval, verdict) on the clutter error, OSPA (history and
    online views), false tracks, ids and HOTA. Writes OUT/results.json and OUT/report.md
    (and OUT/report.html with --html). Exit status 1 if any job failed.
    """
    from mhtrack.experiments import clutter_scenes as cs
    from mhtrack.reports.clutter_scenes import pair_summary, write_clutter_scenes_report

    if html:  # before the study, not after it: as ``report``, one line and exit 1
        from mhtrack.reports.html_page import require_plotly

        try:
            require_plotly()
        except ImportError as e:
            raise click.ClickException(str(e)) from None
    run_on = executor_kwargs(workers, dask_scheduler)
    try:
        from mhtrack.scenario import preset

        base = preset(cs.PRESET, scans=scans)
        with resume_on_interrupt("reproduce clutter-scenes", out):
            study = cs.clutter_scenes(out, runs, seed, base=base, scenes=scenes or None,
                                      methods=methods or None, **run_on)
    except ValueError as e:
        raise InputProblem(str(e)) from None
    rep = write_clutter_scenes_report(study)
    if html:
        from mhtrack.reports.html_clutter_scenes import write_clutter_scenes_html

        try:
            rep.paths.insert(2, write_clutter_scenes_html(study))
        except ImportError as e:
            raise click.ClickException(str(e)) from None
    for line in pair_summary(study.paired.get(cs.POOLED, next(iter(study.paired.values()),
                                                              []))):
        say(f"* {line}")
    say(f"{study.computed} jobs computed, {study.skipped} already done.")
    _wrote(rep.paths)
    _exit_if_jobs_failed("clutter-scenes", study.errors, f"{out}/jobs/")


def _wrote(paths: Any) -> None:
    """List the files and folders a study wrote (folders with a trailing ``/``)."""
    say("wrote:")
    for p in paths:
        say(f"  {p}{'/' if p.is_dir() else ''}")


def _exit_if_jobs_failed(study: str, errors: Any, where: str) -> None:
    """One line naming the failed jobs (the first ten) and where their tracebacks are,
    then exit status 1; nothing when no job failed."""
    if errors:
        names = sorted(errors)
        click.echo(f"mhtrack reproduce {study}: {len(names)} job(s) failed "
                   f"({', '.join(names[:10])}); tracebacks in {where}", err=True)
        click.get_current_context().exit(1)


COMMANDS = [reproduce]
