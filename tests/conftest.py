"""Hooks for the whole suite (loaded by pytest-xdist's controller too)."""

from __future__ import annotations

# Every command gets the shared options (-q/--quiet, --progress, -v, --log-file) when the
# ``mhtrack`` group is assembled; tests that invoke a command object directly would
# otherwise see them or not depending on which test imported the group first.
import mhtrack.cli.main  # noqa: F401


def pytest_terminal_summary(terminalreporter) -> None:
    """The measurements the browser tests record (``record_property("measured", …)``),
    one line each at the end of the run (also from pytest-xdist's workers)."""
    lines = [v for r in terminalreporter.stats.get("passed", [])
             for k, v in getattr(r, "user_properties", []) if k == "measured"]
    if lines:
        terminalreporter.write_sep("-", "measured in the browser")
        for line in lines:
            terminalreporter.write_line(line)
