"""What the command line shows and logs: ``-v`` / ``-vv``, ``--log-file FILE``, ``-q`` /
``--quiet`` and ``--progress``, on the group (``mhtrack -v track …``) and on every command
(``mhtrack track … -v``), all from :func:`shared_options`.

* mhtrack's own logger (``mhtrack`` and its children) logs at WARNING, INFO with ``-v``
  (each command's summary), DEBUG with ``-vv`` (per-frame / per-scan progress where the
  library reports it);
* every other logger (matplotlib, numba, distributed, …) stays at WARNING whatever the
  verbosity, so ``-vv`` shows mhtrack's lines, not a library's font search;
* ``--log-file FILE`` appends the same lines, time-stamped, to FILE, at INFO at least
  (DEBUG with ``-vv``), whatever stderr shows;
* ``--quiet`` silences the progress bar, the info lines (:func:`mhtrack.cli.terminal.say`)
  and the warnings on stderr (errors still show; the log file still gets every line);
  ``--progress`` draws the bar even when stderr is no terminal (by default it is drawn
  only on a terminal). Precedence: ``--quiet`` over ``--progress`` over the terminal
  check, and ``--quiet`` over ``-v`` on stderr. ``--no-progress`` (hidden, kept for a
  release) turns the bar off and leaves the lines alone.
"""

from __future__ import annotations

import logging
import sys
from dataclasses import dataclass
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


def configure(verbose: int = 0, log_file: str | Path | None = None,
              quiet: bool = False) -> None:
    """Set mhtrack's logger to :func:`level_of` ``verbose`` (the log file's to INFO at
    least), every other logger to WARNING, and (re)install the stderr and file handlers
    on the root logger; ``quiet``: stderr shows errors only."""
    for h in _installed:
        logging.getLogger().removeHandler(h)
        h.close()
    _installed.clear()
    stderr_level = logging.ERROR if quiet else level_of(verbose)
    err = _Stderr()
    err.setLevel(stderr_level)
    err.setFormatter(logging.Formatter(STDERR_FORMAT))
    _installed.append(err)
    own = stderr_level
    if log_file is not None:
        fh = logging.FileHandler(log_file, mode="a", encoding="utf-8", delay=False)
        file_level = min(level_of(verbose), logging.INFO)
        fh.setLevel(file_level)
        fh.setFormatter(logging.Formatter(FILE_FORMAT))
        _installed.append(fh)
        own = min(own, file_level)
    root = logging.getLogger()
    root.setLevel(logging.WARNING)
    for h in _installed:
        root.addHandler(h)
    logging.getLogger("mhtrack").setLevel(own)


@dataclass(frozen=True)
class Shown:
    """What this invocation asked to see: the group's options and the command's, merged
    (``-v`` counts add up; a flag given on either counts)."""

    verbose: int = 0
    log_file: Path | None = None
    quiet: bool = False
    #: ``--progress`` (True), ``--no-progress`` (False), neither (None).
    progress: bool | None = None


#: The shared options: (flags, name, help); ``-v`` counts, ``--log-file`` takes a FILE,
#: the others are flags. Names are the group's parameters (a command's are ``command_``
#: and the name, kept in ``ctx.meta``).
_OPTIONS: tuple[tuple[tuple[str, ...], str, str], ...] = (
    (("-v", "--verbose"), "verbose", "More log output: -v mhtrack's summaries, -vv its "
     "per-frame lines (other libraries stay at warnings)."),
    (("--log-file",), "log_file", "Append mhtrack's log (INFO at least, time-stamped) to "
     "FILE."),
    (("-q", "--quiet"), "quiet", "No progress bar, info lines or warnings on the terminal "
     "(errors and the results asked for still print; --log-file still logs). Wins over "
     "--progress and -v."),
    (("--progress",), "progress", "Draw the progress bar on stderr even when it is no "
     "terminal [drawn only on a terminal]."),
    (("--no-progress",), "no_progress", "No progress bar (the former spelling)."),
)


def shared_options(group: bool = False) -> list[click.Option]:
    """``-v``, ``--log-file``, ``-q/--quiet``, ``--progress`` (and the hidden
    ``--no-progress``): the group's (values passed to its function), or a command's
    (kept in ``ctx.meta``; each reconfigures logging as it is parsed)."""
    out = []
    for flags, name, text in _OPTIONS:
        kw: dict[str, Any] = {"help": text, "hidden": name == "no_progress"}
        if name == "verbose":
            kw["count"] = True
        elif name == "log_file":
            kw.update(type=click.Path(dir_okay=False, path_type=Path), default=None)
        else:
            kw["is_flag"] = True
        if not group:
            kw.update(expose_value=False, callback=_store(name))
            name = f"command_{name}"
        out.append(click.Option([*flags, name], **kw))
    return out


def _store(name: str) -> Any:
    """The callback of a command's option ``name``: keep its value, reconfigure."""
    def callback(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
        ctx.meta[f"mhtrack.{name}"] = value
        s = shown(ctx)
        configure(s.verbose, s.log_file, s.quiet)
        return value

    return callback


def shown(ctx: click.Context | None = None) -> Shown:
    """:class:`Shown` of ``ctx`` (default: the current click context; none: defaults)."""
    ctx = click.get_current_context(silent=True) if ctx is None else ctx
    if ctx is None:
        return Shown()
    root = ctx.find_root()
    group = root.params if root is not ctx else {}
    meta = ctx.meta

    def flag(name: str) -> bool:
        return bool(group.get(name)) or bool(meta.get(f"mhtrack.{name}"))

    progress = True if flag("progress") else (False if flag("no_progress") else None)
    return Shown(verbose=int(group.get("verbose") or 0) + int(meta.get("mhtrack.verbose") or 0),
                 log_file=meta.get("mhtrack.log_file") or group.get("log_file"),
                 quiet=flag("quiet"), progress=progress)
