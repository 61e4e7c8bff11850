"""Opening a tracker's input: a plots table (scans or timed plots) or an ASTERIX
recording, with the scenario or sensors file given or found beside it.

The rules, in one place: timed plots and recordings take a sensors file (default
``sensors.toml`` beside them; a recording needs one), never a scenario; a scans table
takes a scenario (default ``scenario.toml`` beside it) or a sensors file, not both.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mhtrack.sources.base import Source

log = logging.getLogger("mhtrack")

#: Files looked for beside the plots when none is given.
SENSORS_BESIDE = "sensors.toml"
SCENARIO_BESIDE = "scenario.toml"


def beside(path: Path, name: str) -> Path | None:
    """``name`` in the directory of ``path``, if that file exists."""
    p = path.parent / name
    return p if p.is_file() else None


def input_files(path: str | Path, scenario_file: str | Path | None = None,
                sensors_file: str | Path | None = None) -> tuple[Path | None, Path | None]:
    """``(scenario file, sensors file)`` of ``mhtrack track PATH`` by the module
    docstring's rules (given, else found beside the plots); conflicting or missing files
    raise :class:`ValueError`."""
    from mhtrack.io.asterix import is_recording
    from mhtrack.io.plots import is_timed

    path = Path(path)
    scenario = None if scenario_file is None else Path(scenario_file)
    sensors = None if sensors_file is None else Path(sensors_file)
    recording = is_recording(path)
    if recording or is_timed(path):
        if scenario is not None:
            kind = ("is an ASTERIX recording (timed plots)" if recording
                    else "holds timed plots (no scan column)")
            raise ValueError(f"{path} {kind}: give their sensors with --sensors FILE, "
                             "not --scenario")
        sensors = sensors or beside(path, SENSORS_BESIDE)
        if recording and sensors is None:
            raise ValueError(f"{path} is an ASTERIX recording: give its radars with "
                             "--sensors FILE (id = SAC·256 + SIC, lat, lon, alt)")
        return None, sensors
    if scenario is not None and sensors is not None:
        raise ValueError("give --scenario (scans) or --sensors (timed plots), not both")
    if sensors is not None:
        return None, sensors
    return scenario or beside(path, SCENARIO_BESIDE), None


def open_input(path: str | Path, *, scenario_file: str | Path | None = None,
               sensors_file: str | Path | None = None,
               reorder_window_s: float | None = None, sectors: bool = False) -> Source:
    """The source of ``mhtrack track PATH``: the files of :func:`input_files` read, and
    the plots table or recording opened with them (``sectors``: as
    :func:`~mhtrack.sources.open_source`)."""
    scenario_file, sensors_file = input_files(path, scenario_file, sensors_file)
    sensors = scenario = None
    if sensors_file is not None:
        from mhtrack.io.sensors import read_sensors

        sensors = read_sensors(sensors_file)
    if scenario_file is not None:
        from mhtrack.scenario import load_scenario

        scenario = load_scenario(scenario_file)
    from mhtrack.sources import open_source

    return open_source(path, sensors=sensors, scenario=scenario,
                       reorder_window_s=reorder_window_s, sectors=sectors)
