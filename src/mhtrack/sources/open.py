"""Which source reads a file: :func:`open_source` looks at the content, as ``mhtrack
track`` does — an ASTERIX recording (:func:`mhtrack.io.asterix.api.is_recording`), else a
plots table, timed or with scans (:func:`mhtrack.io.plots.is_timed`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from mhtrack.io._source import PathArg
from mhtrack.sources.base import Source

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet
    from mhtrack.scenario import Scenario


def open_source(path: PathArg, *, sensors: SensorSet | None = None,
                scenario: Scenario | None = None,
                reorder_window_s: float | None = None, sectors: bool = False) -> Source:
    """The :class:`Source` of a plots table or an ASTERIX recording at ``path``.

    ``sensors``: the radars of timed plots and recordings (a recording without them, or
    with radars they lack, uses the sites the radars send in CAT034, and skips radars
    without one: :mod:`mhtrack.io.asterix.sites`);
    ``scenario``: the sensors and scan times of a scan table; ``reorder_window_s``: the
    re-order window of timed plots (default
    :data:`~mhtrack.io.reorder.DEFAULT_REORDER_WINDOW_S`); ``sectors``: a recording's
    frames cut at its radars' own CAT034 sector crossings (``docs/real-radar.md``; a
    plots table has none: refused). Nothing else is guessed:
    a sensors file beside the plots is the caller's choice."""
    from mhtrack.io.asterix.api import is_recording

    if is_recording(path):
        if scenario is not None:
            raise ValueError(f"{path} is an ASTERIX recording: its radars come from a "
                             "sensors file, not a scenario")
        from mhtrack.sources.recording import AsterixSource

        return AsterixSource(path, sensors=sensors, reorder_window_s=reorder_window_s,
                             sectors=sectors)
    if sectors:
        raise ValueError(f"{path} is a plots table: frames at the radars' own sectors need "
                         "a recording with their CAT034 sector crossings")
    from mhtrack.sources.tables import TableSource

    return TableSource(path, sensors=sensors, scenario=scenario,
                       reorder_window_s=reorder_window_s)
