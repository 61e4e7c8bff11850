"""``convert`` and ``export``: ASTERIX recordings (CAT048/CAT034 in pcap, pcapng or raw
files) to plots tables and back; and the hook through which ``track`` reads a recording.
The work is in :mod:`mhtrack.io.asterix`."""

from __future__ import annotations

import logging
import tempfile
from collections.abc import Callable
from functools import wraps
from pathlib import Path
from typing import Any

import click

_EXISTING = click.Path(exists=True, dir_okay=False, path_type=Path)


def _needs_libasterix(f: Callable[..., Any]) -> Callable[..., Any]:
    """A missing libasterix becomes one line naming ``pip install 'mhtrack[asterix]'``."""

    @wraps(f)
    def run(*args: Any, **kwargs: Any) -> Any:
        try:
            return f(*args, **kwargs)
        except ModuleNotFoundError as e:
            from mhtrack.io.asterix._lib import MissingExtra

            if isinstance(e, MissingExtra):
                raise click.ClickException(str(e)) from None
            raise

    return run


def _read_recording(path: Path) -> Any:
    """Decode ``path``, warning one line per kind of skipped part."""
    from mhtrack.io.asterix import read_recording

    rec = read_recording(path)
    rec.problems.warn(str(path))
    return rec


@click.command()
@click.argument("recording", type=_EXISTING)
@click.argument("output", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--sensors", "sensors_file", type=_EXISTING, default=None,
              help="Sensors file (TOML) with the radars' sites (id = SAC·256 + SIC, lat, "
              "lon, alt): adds the ground range column 'range'.")
@_needs_libasterix
def convert(recording: Path, output: Path, sensors_file: Path | None) -> None:
    """Decode an ASTERIX RECORDING (CAT048 plots, CAT034 sweeps; pcap, pcapng or raw
    data blocks, recognised by content) into a plots OUTPUT (.csv or .parquet)."""
    from mhtrack.io.asterix import convert as run_convert
    from mhtrack.io.paths import check_output_file
    from mhtrack.io.sensors import read_sensors

    check_output_file(output, inputs=(recording, sensors_file), what="plots file")
    sensors = read_sensors(sensors_file) if sensors_file is not None else None
    done = run_convert(recording, output, sensors, recording=_read_recording(recording))
    rec = done.recording
    radars = ", ".join(f"{s >> 8}/{s & 0xFF}" for s in sorted(set(rec.plots["sensor"]
                                                                   .tolist())))
    periods = ", ".join(f"{s}: {p:.3g} s" for s, p in sorted(rec.periods().items()))
    click.echo(f"{rec.container} recording: {done.n_plots} plots from radars (SAC/SIC) "
               f"{radars}; {rec.sweeps['time'].size} CAT034 sweep marks"
               + (f" (periods {periods})" if periods else "") + f" -> {output}")


@click.command()
@click.argument("plots", type=_EXISTING)
@click.option("--sensors", "sensors_file", type=_EXISTING, default=None,
              help="Sensors file (TOML): sites (lat, lon, alt) for the slant range, and "
              "periods for the CAT034 north markers [required for 048; for 062 only for "
              "tracks without lat/lon].")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), required=True,
              help="Recording to write: .pcap (UDP datagrams) or .ast (raw data blocks).")
@click.option("--category", type=click.Choice(["048", "062"]), default="048",
              show_default=True, help="048: PLOTS are timed plots, written as CAT048 target "
              "reports with CAT034 sweeps; 062: PLOTS is a tracks file, written as CAT062 "
              "system tracks.")
@click.option("--sac", type=click.IntRange(0, 255), default=0, show_default=True,
              help="CAT062: the tracker's system area code (I062/010).")
@click.option("--sic", type=click.IntRange(0, 255), default=1, show_default=True,
              help="CAT062: the tracker's system identification code (I062/010).")
@_needs_libasterix
def export(plots: Path, sensors_file: Path | None, out: Path, category: str, sac: int,
           sic: int) -> None:
    """Encode timed PLOTS (time, sensor, range or slant_range, bearing) as ASTERIX
    CAT048 target reports with CAT034 north markers and sector crossings; or, with
    --category 062, a TRACKS file as CAT062 system tracks."""
    from mhtrack.io.asterix import export as run_export
    from mhtrack.io.asterix.cat062 import export_tracks
    from mhtrack.io.paths import check_output_file
    from mhtrack.io.sensors import read_sensors

    check_output_file(out, inputs=(plots, sensors_file), suffixes=(".pcap", ".ast"),
                      what="recording")
    sensors = read_sensors(sensors_file) if sensors_file is not None else None
    if category == "062":
        n, blocks = export_tracks(plots, sensors, out, sac=sac, sic=sic)
        click.echo(f"{n} track updates in {blocks} data blocks (CAT062) -> {out}")
        return
    if sensors is None:
        raise click.UsageError("export of plots (CAT048) needs --sensors FILE")
    n, blocks = run_export(plots, sensors, out)
    click.echo(f"{n} plots in {blocks} data blocks (CAT048, CAT034) -> {out}")


@_needs_libasterix
def recording_hook(plots: Path, sensors_file: Path | None) -> tuple[Path, Path | None]:
    """``track``'s input: a recording becomes a temporary plots file (with ``range``) and
    sensors file (periods from CAT034 filled in), removed when the command ends; any
    other file passes through unchanged."""
    from mhtrack.io.asterix import is_recording

    if not is_recording(plots):
        return plots, sensors_file
    from mhtrack.errors import InputError
    from mhtrack.io.asterix import convert as run_convert
    from mhtrack.io.asterix import sensors_with_periods
    from mhtrack.io.sensors import read_sensors, write_sensors

    if sensors_file is None and (plots.parent / "sensors.toml").is_file():
        sensors_file = plots.parent / "sensors.toml"
    if sensors_file is None:
        raise click.UsageError(f"{plots} is an ASTERIX recording: give its radars with "
                               "--sensors FILE (id = SAC·256 + SIC, lat, lon, alt)")
    sensors = read_sensors(sensors_file)
    rec = _read_recording(plots)
    missing = sorted(set(rec.plots["sensor"].tolist()) - set(sensors.ids))
    if missing:
        shown = ", ".join(f"{s} (SAC {s >> 8}, SIC {s & 0xFF})" for s in missing)
        raise InputError(f"{plots}: radar(s) {shown} are not in {sensors_file} (it lists "
                         f"{', '.join(map(str, sensors.ids))}); add them, id = SAC·256 + "
                         "SIC", file=str(plots))
    tmp = tempfile.TemporaryDirectory(prefix="mhtrack-asterix-")
    click.get_current_context().call_on_close(tmp.cleanup)
    sensors = sensors_with_periods(sensors, rec)
    out, sens = Path(tmp.name) / "plots.parquet", Path(tmp.name) / "sensors.toml"
    run_convert(plots, out, sensors, recording=rec)
    write_sensors(sensors, sens)
    logging.getLogger("mhtrack").info("%s: %d plots decoded", plots, len(rec))
    return out, sens


COMMANDS = [convert, export]
