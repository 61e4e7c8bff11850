"""Opening a tracker's input: a plots table (scans or timed plots) or an ASTERIX
recording, with the scenario or sensors file given or found beside it.

The rules, in one place: timed plots and recordings take a sensors file (default
``sensors.toml`` beside them; a recording needs one), never a scenario; a scans table
takes a scenario (default ``scenario.toml`` beside it) or a sensors file, not both.
"""

from __future__ import annotations

import dataclasses
import logging
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from mhtrack.sources.memory import MemorySource

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet
    from mhtrack.sources.base import Source

log = logging.getLogger("mhtrack")

#: Files looked for beside the plots when none is given.
SENSORS_BESIDE = "sensors.toml"
SCENARIO_BESIDE = "scenario.toml"


def beside(path: Path, name: str) -> Path | None:
    """``name`` in the directory of ``path``, if that file exists."""
    p = path.parent / name
    return p if p.is_file() else None


def open_input(path: str | Path, *, scenario_file: str | Path | None = None,
               sensors_file: str | Path | None = None,
               reorder_window_s: float | None = None) -> Source:
    """The source of ``mhtrack track PLOTS``: a plots table or a recording, read through
    today's readers (the whole table in memory, :class:`~mhtrack.sources.memory.MemorySource`),
    with the sensors or scenario of the module docstring's rules. Conflicting files
    raise :class:`ValueError`."""
    from mhtrack.io.asterix import is_recording
    from mhtrack.io.plots import is_timed
    from mhtrack.io.timed_plots import DEFAULT_REORDER_WINDOW_S

    path = Path(path)
    scenario_file = None if scenario_file is None else Path(scenario_file)
    sensors_file = None if sensors_file is None else Path(sensors_file)
    window = DEFAULT_REORDER_WINDOW_S if reorder_window_s is None else reorder_window_s
    if is_recording(path):
        return _recording(path, scenario_file, sensors_file, window)
    if is_timed(path):
        if scenario_file is not None:
            raise ValueError(f"{path} holds timed plots (no scan column): give their "
                             "sensors with --sensors FILE, not --scenario")
        sensors_file = sensors_file or beside(path, SENSORS_BESIDE)
    elif scenario_file is not None and sensors_file is not None:
        raise ValueError("give --scenario (scans) or --sensors (timed plots), not both")
    if sensors_file is not None:
        from mhtrack.io.sensors import read_sensors

        return _table(path, read_sensors(sensors_file), window)
    return _scans(path, scenario_file or beside(path, SCENARIO_BESIDE), window)


def _table(path: Path, sensors: SensorSet, window: float, name: str | None = None,
           read_as: Path | None = None) -> MemorySource:
    from mhtrack.io import read_plots

    table = read_plots(read_as or path, sensors=sensors, reorder_window_s=window)
    return MemorySource(table, name=name or str(path), sensors=sensors)


def _scans(path: Path, scenario_file: Path | None, window: float) -> MemorySource:
    """A scans table (or timed plots without sensors), with its scenario if any."""
    from mhtrack.io import read_plots
    from mhtrack.io.plots import check_scan_times, is_timed

    scenario = None
    if scenario_file is not None and not is_timed(path):
        from mhtrack.scenario import load_scenario

        scenario = load_scenario(scenario_file)
    registry = None if scenario is None else {s.id: s for s in scenario.sensors}
    table = read_plots(path, sensors=registry, reorder_window_s=window)
    if scenario is not None:
        check_scan_times(path, table, scenario.scan_indices(), scenario.scan_times(),
                         f"scenario {scenario_file}")
        table = dataclasses.replace(
            table, scan_times=(scenario.scan_indices(), scenario.scan_times()))
    elif table.range is not None:
        option = "--sensors with the radars" if table.timed else "--scenario with the radar(s)"
        log.warning(
            "%s has range/bearing columns (polar plots), but no %s gives its sensors: they "
            "are ignored and x, y tracked as Cartesian plots with the tracker's σw; pass %s "
            "to use the polar measurement model", path,
            "sensors file" if table.timed else "scenario", option)
    return MemorySource(table, name=str(path), scenario=scenario)


def _recording(path: Path, scenario_file: Path | None, sensors_file: Path | None,
               window: float) -> MemorySource:
    """An ASTERIX recording: decoded, its radars checked against the sensors file and
    their CAT034 periods filled in, its plots read as a timed plots table."""
    from mhtrack.errors import InputError
    from mhtrack.io.asterix import convert, read_recording, sensors_with_periods
    from mhtrack.io.sensors import read_sensors

    if scenario_file is not None:
        raise ValueError(f"{path} is an ASTERIX recording (timed plots): give its sensors "
                         "with --sensors FILE, not --scenario")
    sensors_file = sensors_file or beside(path, SENSORS_BESIDE)
    if sensors_file is None:
        raise ValueError(f"{path} is an ASTERIX recording: give its radars with "
                         "--sensors FILE (id = SAC·256 + SIC, lat, lon, alt)")
    sensors = read_sensors(sensors_file)
    rec = read_recording(path)
    rec.problems.warn(str(path))
    missing = sorted(set(rec.plots["sensor"].tolist()) - set(sensors.ids))
    if missing:
        shown = ", ".join(f"{s} (SAC {s >> 8}, SIC {s & 0xFF})" for s in missing)
        raise InputError(f"{path}: radar(s) {shown} are not in {sensors_file} (it lists "
                         f"{', '.join(map(str, sensors.ids))}); add them, id = SAC·256 + "
                         "SIC", file=str(path))
    sensors = sensors_with_periods(sensors, rec)
    log.info("%s: %d plots decoded", path, len(rec))
    # Until the streaming recording source: the plots go through a table file, read back
    # whole (the same table, hence the same tracks, as before).
    with tempfile.TemporaryDirectory(prefix="mhtrack-asterix-") as tmp:
        table_file = Path(tmp) / "plots.parquet"
        convert(path, table_file, sensors, recording=rec)
        return _table(path, sensors, window, read_as=table_file)
