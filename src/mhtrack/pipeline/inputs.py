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
    from mhtrack.scenario import Scenario
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
               reorder_window_s: float | None = None) -> Source:
    """The source of ``mhtrack track PATH``: the files of :func:`input_files` read, and
    the plots table or recording opened with them."""
    scenario_file, sensors_file = input_files(path, scenario_file, sensors_file)
    sensors = scenario = None
    if sensors_file is not None:
        from mhtrack.io.sensors import read_sensors

        sensors = read_sensors(sensors_file)
    if scenario_file is not None:
        from mhtrack.scenario import load_scenario

        scenario = load_scenario(scenario_file)
    # The one line to change for the streaming sources: open_source(path, ...) of
    # mhtrack.sources (same keywords) in place of read_source.
    return read_source(path, sensors=sensors, scenario=scenario,
                       reorder_window_s=reorder_window_s)


def read_source(path: str | Path, *, sensors: SensorSet | None = None,
                scenario: Scenario | None = None,
                reorder_window_s: float | None = None) -> MemorySource:
    """A plots table or a recording read whole by today's readers
    (:func:`~mhtrack.io.read_plots`, :func:`~mhtrack.io.asterix.read_recording`), as a
    :class:`~mhtrack.sources.memory.MemorySource`; the keywords of
    :func:`mhtrack.sources.open_source`."""
    from mhtrack.io.asterix import is_recording
    from mhtrack.io.timed_plots import DEFAULT_REORDER_WINDOW_S

    path = Path(path)
    window = DEFAULT_REORDER_WINDOW_S if reorder_window_s is None else reorder_window_s
    if is_recording(path):
        if sensors is None:
            raise ValueError(f"{path} is an ASTERIX recording: give its radars with "
                             "--sensors FILE (id = SAC·256 + SIC, lat, lon, alt)")
        return _recording(path, sensors, window)
    if sensors is not None:
        return _table(path, sensors, window)
    return _scans(path, scenario, window)


def _table(path: Path, sensors: SensorSet, window: float,
           read_as: Path | None = None) -> MemorySource:
    from mhtrack.io import read_plots

    table = read_plots(read_as or path, sensors=sensors, reorder_window_s=window)
    return MemorySource(table, name=str(path), sensors=sensors)


def _scans(path: Path, scenario: Scenario | None, window: float) -> MemorySource:
    """A scans table (or timed plots without sensors), with its scenario if any."""
    from mhtrack.io import read_plots
    from mhtrack.io.plots import check_scan_times, is_timed

    if scenario is not None and is_timed(path):
        raise ValueError(f"{path} holds timed plots (no scan column): give their sensors "
                         "with --sensors FILE, not --scenario")
    registry = None if scenario is None else {s.id: s for s in scenario.sensors}
    table = read_plots(path, sensors=registry, reorder_window_s=window)
    if scenario is not None:
        check_scan_times(path, table, scenario.scan_indices(), scenario.scan_times(),
                         f"scenario {scenario.name!r}")
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


def _recording(path: Path, sensors: SensorSet, window: float) -> MemorySource:
    """An ASTERIX recording: decoded, its radars checked against ``sensors`` and their
    CAT034 periods filled in, its plots read as a timed plots table."""
    from mhtrack.errors import InputError
    from mhtrack.io.asterix import convert, read_recording, sensors_with_periods

    rec = read_recording(path)
    rec.problems.warn(str(path))
    missing = sorted(set(rec.plots["sensor"].tolist()) - set(sensors.ids))
    if missing:
        shown = ", ".join(f"{s} (SAC {s >> 8}, SIC {s & 0xFF})" for s in missing)
        raise InputError(f"{path}: radar(s) {shown} are not in the sensors file (it lists "
                         f"{', '.join(map(str, sensors.ids))}); add them, id = SAC·256 + "
                         "SIC", file=str(path))
    sensors = sensors_with_periods(sensors, rec)
    log.info("%s: %d plots decoded", path, len(rec))
    # The plots go through a table file, read back whole (the same table, hence the same
    # tracks, as before the streaming recording source).
    with tempfile.TemporaryDirectory(prefix="mhtrack-asterix-") as tmp:
        table_file = Path(tmp) / "plots.parquet"
        convert(path, table_file, sensors, recording=rec)
        return _table(path, sensors, window, read_as=table_file)
