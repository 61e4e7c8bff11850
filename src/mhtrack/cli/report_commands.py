"""``report``: one self-contained HTML page of a run or a study directory."""

from __future__ import annotations

from pathlib import Path

import click


def write_report_or_fail(directory: Path, output: Path | None = None) -> Path:
    """:func:`~mhtrack.reports.html_report.write_html_report`, the missing optional extra
    turned into one line (exit 1)."""
    try:
        from mhtrack.reports.html_report import write_html_report

        return write_html_report(directory, output)
    except ImportError as e:
        raise click.ClickException(str(e)) from None


@click.command()
@click.argument("directory", type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="HTML file to write [default: DIR/report.html].")
def report(directory: Path, output: Path | None) -> None:
    """Write one self-contained HTML page of DIR (opens from disk, no network).

    DIR is a run (``run``'s output, or plots, truth, tracks and sensors files, with
    metrics.json from ``evaluate --json`` if you have it) or a ``montecarlo`` study. The
    page holds the scene (zoom, pan), OSPA, OSPA(2) when evaluated, and cardinality per
    scan, the metrics, the parameters and caps, and for studies the paired comparisons.
    Needs the optional extra: pip install "mhtrack[report]".
    """
    from mhtrack.io.paths import check_output_file

    if output is not None:
        check_output_file(output, inputs=(), suffixes=(".html",), what="report", option="-o")
    path = write_report_or_fail(directory, output)
    click.echo(f"wrote {path}")


COMMANDS = [report]
