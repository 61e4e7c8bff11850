"""The ``mhtrack`` command of this checkout, run from a benchmark script: ``CLI`` (the
command line), ``env()`` (the environment with this checkout's ``src`` first on
``PYTHONPATH``) and ``run(args)`` (one command to the end, its standard output; ``echo_run`` prints
it first)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
CLI = [sys.executable, "-c", "from mhtrack.cli.main import main; main()"]


def env() -> dict[str, str]:
    """``os.environ`` with this checkout's ``src`` before any ``PYTHONPATH``."""
    return {**os.environ, "PYTHONPATH": str(SRC) + os.pathsep + os.environ.get(
        "PYTHONPATH", "")}


def run(args: list[str]) -> str:
    """``mhtrack ARGS`` to the end (an error raises); its standard output."""
    return subprocess.run([*CLI, *args], capture_output=True, text=True, env=env(),
                          check=True).stdout


def echo_run(args: list[str]) -> str:
    """:func:`run`, the command printed first."""
    print("$ mhtrack " + " ".join(args), flush=True)
    return run(args)
