"""Logging of the command line: ``-v`` / ``-vv`` and ``--log-file FILE``, on the group
(``mhtrack -v track …``) and on every command (``mhtrack track … -v``).

* mhtrack's own logger (``mhtrack`` and its children) logs at WARNING, INFO with ``-v``
  (each command's summary), DEBUG with ``-vv`` (per-frame / per-scan progress where the
  library reports it);
* every other logger (matplotlib, numba, distributed, …) stays at WARNING whatever the
  verbosity, so ``-vv`` shows mhtrack's lines, not a library's font search;
* ``--log-file FILE`` appends the same lines, time-stamped, to FILE, at INFO at least
  (DEBUG with ``-vv``), whatever stderr shows.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path
from typing import Any

import click

#: The format on stderr, and in the log file (with the time first).
STDERR_FORMAT = "mhtrack: %(levelname)s: %(message)s"
FILE_FORMAT = "%(asctime)s %(name)s %(levelname)s: %(message)s"


class _Stderr(logging.StreamHandler):  # type: ignore[type-arg]
    """A handler writing to whatever ``sys.stderr`` is when a record comes (click's test
    runner and pytest swap it), never to a stream closed since."""

    def __init__(self) -> None:
        super().__init__(sys.stderr)

    @property  # type: ignore[override]
    def stream(self) -> Any:
        return sys.stderr

    @stream.setter
    def stream(self, value: Any) -> None:
        pass


#: The handlers this module installed on the root logger (replaced on each configure).
_installed: list[logging.Handler] = []
def level_of(verbose: int) -> int:
    """WARNING, INFO (``-v``), DEBUG (``-vv`` or more)."""
    return logging.WARNING - 10 * min(max(verbose, 0), 2)


def configure(verbose: int = 0, log_file: str | Path | None = None) -> None:
    """Set mhtrack's logger to :func:`level_of` ``verbose`` (the log file's to INFO at
    least), every other logger to WARNING, and (re)install the stderr and file handlers
    on the root logger."""
    for h in _installed:
        logging.getLogger().removeHandler(h)
        h.close()
    _installed.clear()
    stderr_level = level_of(verbose)
    err = _Stderr()
    err.setLevel(stderr_level)
    err.setFormatter(logging.Formatter(STDERR_FORMAT))
    _installed.append(err)
    own = stderr_level
    if log_file is not None:
        fh = logging.FileHandler(log_file, mode="a", encoding="utf-8", delay=False)
        file_level = min(stderr_level, logging.INFO)
        fh.setLevel(file_level)
        fh.setFormatter(logging.Formatter(FILE_FORMAT))
        _installed.append(fh)
        own = min(own, file_level)
    root = logging.getLogger()
    root.setLevel(logging.WARNING)
    for h in _installed:
        root.addHandler(h)
    logging.getLogger("mhtrack").setLevel(own)


def _apply(ctx: click.Context, key: str, value: Any) -> None:
    """Configure from this invocation alone: the group's ``-v``/``--log-file`` (when the
    command runs under the ``mhtrack`` group) plus the command's own."""
    ctx.meta[key] = value
    root = ctx.find_root()
    group = root.params if root is not ctx else {}
    verbose = int(group.get("verbose") or 0) + int(ctx.meta.get("mhtrack.verbose") or 0)
    log_file = ctx.meta.get("mhtrack.log_file") or group.get("log_file")
    configure(verbose, log_file)


def _verbose_callback(ctx: click.Context, param: click.Parameter, value: int) -> int:
    _apply(ctx, "mhtrack.verbose", value)
    return value


def _log_file_callback(ctx: click.Context, param: click.Parameter, value: Path | None
                       ) -> Path | None:
    _apply(ctx, "mhtrack.log_file", value)
    return value


def logging_params() -> list[click.Option]:
    """``-v/--verbose`` and ``--log-file`` for a command (they add to the group's)."""
    return [
        click.Option(["-v", "--verbose", "command_verbose"], count=True, expose_value=False,
                     callback=_verbose_callback,
                     help="More log output: -v mhtrack's summaries, -vv its per-frame "
                     "progress (other libraries stay at warnings)."),
        click.Option(["--log-file", "command_log_file"], expose_value=False,
                     type=click.Path(dir_okay=False, path_type=Path), default=None,
                     callback=_log_file_callback,
                     help="Append mhtrack's log (INFO at least, time-stamped) to FILE."),
    ]
