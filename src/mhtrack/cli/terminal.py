"""What the commands show on the terminal: the progress bar, and what to do after Ctrl-C.

* :func:`progress_option` — ``--progress/--quiet`` (``--no-progress`` an alias of
  ``--quiet``) on every long command; :func:`progress_enabled` turns it into the one
  boolean the library takes: the bar is drawn iff stderr is a terminal, unless an option
  says otherwise — so logs and pipes get no bar.
* :func:`resume_on_interrupt` — Ctrl-C during a study: finished jobs are already stored
  (the job store writes each one as it ends, atomically), the workers are stopped, and
  the command says how to resume, with the exact command, then exits with status 130.
"""

from __future__ import annotations

import contextlib
import os
import shlex
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import click

#: Exit status after Ctrl-C (128 + SIGINT), as shells report it.
INTERRUPTED_EXIT = 130


def progress_option(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--progress/--quiet``: the progress bar on stderr [shown iff stderr is a terminal]."""
    return click.option(
        "--progress/--quiet", " /--no-progress", "progress", default=None,
        help="Progress bar on stderr, or none (--quiet, --no-progress) [shown when stderr "
        "is a terminal].")(f)


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
