"""``report``: one HTML page of a run, a recording or a study directory."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from mhtrack.cli.terminal import say, show_progress


def write_report_or_fail(directory: Path, output: Path | None = None, *,
                         plotlyjs: str | None = None, progress: bool = False,
                         coastlines: bool = False) -> Path:
    """:func:`~mhtrack.reports.html_report.write_html_report` (``plotlyjs`` ``None``: its
    default), the missing optional extra turned into one line (exit 1)."""
    try:
        from mhtrack.reports.html_report import write_html_report

        js = {} if plotlyjs is None else {"plotlyjs": plotlyjs}
        return write_html_report(directory, output, progress=progress,
                                 coastlines=coastlines, **js)
    except ImportError as e:
        raise click.ClickException(str(e)) from None


def page_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """The page's options, ``--plotlyjs`` and ``--coastlines``, of every command that
    writes a report (``report``, ``run --report``)."""
    for opt in reversed([
        click.option("--plotlyjs", type=click.Choice(["inline", "file"]), default=None,
                     help="Plotly's JavaScript (4.8 MB) inlined in the page (one "
                     "self-contained file), or written once beside it as "
                     "plotly-VERSION.min.js and shared by every report in that folder "
                     "[inline]."),
        click.option("--coastlines", is_flag=True, help="Draw Natural Earth's coastlines "
                     "and borders (public domain) in a geographic scene: downloaded once "
                     "into the user's cache ($MHTRACK_CACHE, else ~/.cache/mhtrack), left "
                     "off with a note on the page where unavailable."),
    ]):
        f = opt(f)
    return f


@click.command()
@click.argument("directory", type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--out", "-o", "out", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="HTML file to write [default: DIR/report.html].")
@click.option("--output", "output_alias", type=click.Path(dir_okay=False, path_type=Path),
              default=None, hidden=True)  # the former spelling, kept for a release
@page_options
def report(directory: Path, out: Path | None, output_alias: Path | None,
           plotlyjs: str | None, coastlines: bool) -> None:
    """Write one HTML page of DIR (opens from disk, no network).

    DIR is a run (``run``'s output, or plots, truth, tracks and sensors files, with
    metrics.json from ``evaluate --json`` if you have it), a recording (plots, sensors and
    tracks, no truth) or a ``montecarlo`` study. The page holds the scene (zoom, pan,
    hover a track for its details), per-radar plot counts and update intervals, track
    durations; with truth, OSPA, OSPA(2) when evaluated, cardinality per scan and the
    metrics; the parameters and caps; for studies the paired comparisons.
    Needs the optional extra: pip install "mhtrack[report]".
    """
    from mhtrack.io.paths import check_output_file

    out = out if out is not None else output_alias
    if out is not None:
        check_output_file(out, inputs=(), suffixes=(".html",), what="report", option="--out")
    path = write_report_or_fail(directory, out, plotlyjs=plotlyjs,
                                progress=show_progress(), coastlines=coastlines)
    say(f"wrote {path}")


COMMANDS = [report]
