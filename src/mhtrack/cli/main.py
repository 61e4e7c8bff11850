"""The ``mhtrack`` command line: parse, call the library, print. Nothing else lives here.

Every command is reachable from Python through the library functions it calls. Bad input
gives exit status 2 (as a usage error does) and one line on stderr (set ``MHTRACK_DEBUG=1``
for the traceback).
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
from pathlib import Path

import click

from mhtrack import __version__
from mhtrack.cli import logs
from mhtrack.cli.common import InputProblem, bound_number_options
from mhtrack.errors import printable

#: Errors that are the user's input, not a bug: reported as one line, no traceback.
USER_ERRORS: tuple[type[BaseException], ...] = (ValueError, OSError, KeyError)


class Group(click.Group):
    """A click group that turns user errors into one clear line on stderr."""

    def invoke(self, ctx: click.Context) -> object:
        try:
            return super().invoke(ctx)
        except (click.ClickException, click.exceptions.Exit, click.Abort):
            raise
        except USER_ERRORS as exc:
            if os.environ.get("MHTRACK_DEBUG"):
                raise
            msg = printable(str(exc) or type(exc).__name__)
            if isinstance(exc, KeyError):
                msg = f"missing key {msg}"
            raise InputProblem(msg) from None


@click.group(cls=Group, context_settings={"help_option_names": ["-h", "--help"]},
             params=logs.shared_options(group=True))
@click.version_option(__version__, prog_name="mhtrack")
def cli(verbose: int, log_file: Path | None, quiet: bool, progress: bool,
        no_progress: bool) -> None:
    """Multiple-target tracking in unknown, varying clutter (MHT, MHT-GMM, MHT-AGMM) and
    multi-radar track initiation.

    -v, --log-file, -q/--quiet and --progress are also accepted after the command."""
    from mhtrack.io.atomic import install_signal_cleanup

    logs.configure(verbose, log_file, quiet)
    install_signal_cleanup()  # SIGTERM/SIGINT remove the temporaries of writes in flight
    for stream in (sys.stdout, sys.stderr):  # file names that are not UTF-8 print as \xNN
        with contextlib.suppress(AttributeError, ValueError, io.UnsupportedOperation):
            stream.reconfigure(errors="backslashreplace")


def _short_out(command: click.Command) -> None:
    """``-o`` as the short form of ``--out`` (when the command has ``--out`` and no
    ``-o`` of its own)."""
    taken = {o for p in command.params for o in (*p.opts, *p.secondary_opts)}
    for p in command.params:
        if isinstance(p, click.Option) and "--out" in p.opts and "-o" not in taken:
            p.opts.append("-o")


def _every_command(command: click.Command) -> None:
    """The options every command has: ``-v``, ``--log-file``, ``-q/--quiet``,
    ``--progress`` (:func:`mhtrack.cli.logs.shared_options`) and ``-o`` for ``--out``;
    for a group's subcommands too."""
    subs = getattr(command, "commands", None)
    if subs is not None:
        for sub in subs.values():
            _every_command(sub)
        return
    names = {o for p in command.params for o in (*p.opts, *p.secondary_opts)}
    command.params += [p for p in logs.shared_options() if not names & set(p.opts)]
    _short_out(command)


def _register() -> None:
    from mhtrack.cli import (
        asterix_commands,
        clutter_commands,
        data_commands,
        experiment_commands,
        initiation_commands,
        live_commands,
        report_commands,
        reproduce_commands,
        track_commands,
    )

    modules = (data_commands, track_commands, clutter_commands, initiation_commands,
               experiment_commands, reproduce_commands, asterix_commands,
               report_commands, live_commands)
    for module in modules:
        for command in module.COMMANDS:
            cli.add_command(command)
    for command in cli.commands.values():
        _every_command(command)
    bound_number_options(cli)


_register()


def main() -> None:
    """Console-script entry point."""
    cli(prog_name="mhtrack")
