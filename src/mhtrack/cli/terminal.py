"""What the commands show on the terminal: the progress bar, the info lines, and what to
do after Ctrl-C.

* :func:`show_progress` — the one boolean the library takes (``progress=``) from the
  options every command has (``-q/--quiet``, ``--progress``: :mod:`mhtrack.cli.logs`):
  the bar is drawn iff stderr is a terminal, unless an option says otherwise — so logs,
  pipes and tests get no bar;
* :func:`say` — an info line (what a command did: its summary, a note, ``wrote FILE``),
  silenced by ``--quiet``; the results a command was asked for (``evaluate``'s table,
  ``--json``) and errors are printed with :func:`click.echo` whatever ``--quiet`` says.
* :func:`resume_on_interrupt` — Ctrl-C during a study: finished jobs are already stored
  (the job store writes each one as it ends, atomically), the workers are stopped, and
  the command says how to resume, with the exact command, then exits with status 130.
"""

from __future__ import annotations

import contextlib
import os
import shlex
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click

#: Exit status after Ctrl-C (128 + SIGINT), as shells report it.
INTERRUPTED_EXIT = 130


def progress_enabled(progress: bool | None, stream: Any = None) -> bool:
    """``progress`` when the user chose (``--progress`` / ``--quiet``), else whether
    ``stream`` (default ``sys.stderr``) is a terminal."""
    if progress is not None:
        return bool(progress)
    stream = sys.stderr if stream is None else stream
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty()) if isatty is not None else False
    except (OSError, ValueError):  # a closed or detached stream
        return False


def show_progress() -> bool:
    """Whether this invocation draws progress bars: never with ``--quiet``; always with
    ``--progress``; else iff stderr is a terminal (:func:`progress_enabled`)."""
    from mhtrack.cli.logs import shown

    s = shown()
    return False if s.quiet else progress_enabled(s.progress)


def say(text: str, *, err: bool = False, nl: bool = True) -> None:
    """Print the info line ``text`` (stdout, or stderr with ``err``; ``nl`` as for
    :func:`click.echo`) unless ``--quiet``."""
    from mhtrack.cli.logs import shown

    if not shown().quiet:
        click.echo(text, err=err, nl=nl)


def rerun_command(argv: list[str] | None = None) -> str:
    """The command line that started this process, as ``mhtrack …`` (shell-quoted)."""
    args = sys.argv[1:] if argv is None else argv
    return shlex.join(["mhtrack", *args])


@contextlib.contextmanager
def resume_on_interrupt(command: str, out: Path) -> Iterator[None]:
    """On Ctrl-C (``KeyboardInterrupt``) inside the block: one message saying what is
    stored in ``out`` and the exact command (with its folder) that resumes, exit 130."""
    try:
        yield
    except KeyboardInterrupt:
        where = "" if Path(out).is_absolute() else f" (from {shlex.quote(os.getcwd())})"
        click.echo(f"\nmhtrack {command}: interrupted; every finished run is stored in "
                   f"{out}/, nothing partial. Resume with{where}:\n  {rerun_command()}",
                   err=True)
        raise click.exceptions.Exit(INTERRUPTED_EXIT) from None
