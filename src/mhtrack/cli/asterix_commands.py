"""``convert`` and ``export``: ASTERIX recordings (CAT048/CAT034 in pcap, pcapng or raw
files) to plots tables and back. The work is in :mod:`mhtrack.io.asterix`."""

from __future__ import annotations

from collections.abc import Callable
from functools import wraps
from pathlib import Path
from typing import Any

import click

from mhtrack.cli.terminal import say, show_progress
from mhtrack.names import EXPORT_CATEGORIES

_EXISTING = click.Path(exists=True, dir_okay=False, path_type=Path)


def needs_libasterix(f: Callable[..., Any]) -> Callable[..., Any]:
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


@click.command()
@click.argument("recording", type=_EXISTING)
@click.argument("output", type=click.Path(dir_okay=False, path_type=Path), required=False,
                metavar="[OUTPUT]")
@click.option("-o", "--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Plots file to write (.csv or .parquet). The positional OUTPUT is the "
              "older spelling of the same, kept for one release.")
@click.option("--sensors", "sensors_file", type=_EXISTING, default=None,
              help="Sensors file (TOML) with the radars' sites (id = SAC·256 + SIC, lat, "
              "lon, alt): adds the ground range column 'range'.")
@needs_libasterix
def convert(recording: Path, output: Path | None, out: Path | None,
            sensors_file: Path | None) -> None:
    """Decode an ASTERIX RECORDING (CAT048 plots, CAT034 sweeps; pcap, pcapng or raw
    data blocks, recognised by content) into a plots file (--out, .csv or .parquet)."""
    target = out or output
    if target is None or (out is not None and output is not None):
        raise click.UsageError("give the plots file to write once: --out FILE (or the "
                               "older positional OUTPUT)")
    output = target
    from mhtrack.io.asterix import convert as run_convert
    from mhtrack.io.paths import check_output_file
    from mhtrack.io.sensors import read_sensors

    check_output_file(output, inputs=(recording, sensors_file), what="plots file")
    sensors = read_sensors(sensors_file) if sensors_file is not None else None
    done = run_convert(recording, output, sensors, progress=show_progress())
    say(f"{done.describe()} -> {output}")


@click.command()
@click.argument("plots", type=_EXISTING)
@click.option("--sensors", "sensors_file", type=_EXISTING, default=None,
              help="Sensors file (TOML): sites (lat, lon, alt) for the slant range, and "
              "periods for the CAT034 north markers [required for 048; for 062 only for "
              "tracks without lat/lon].")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), required=True,
              help="Recording to write: .pcap (UDP datagrams) or .ast (raw data blocks).")
@click.option("--category", type=click.Choice(EXPORT_CATEGORIES),
              default=EXPORT_CATEGORIES[0], show_default=True, help="048: PLOTS are timed "
              "plots, written as CAT048 target reports with CAT034 sweeps; 062: PLOTS is a "
              "tracks file, written as CAT062 system tracks.")
@click.option("--sac", type=click.IntRange(0, 255), default=None,
              help="CAT062: the tracker's system area code (I062/010) [0].")
@click.option("--sic", type=click.IntRange(0, 255), default=None,
              help="CAT062: the tracker's system identification code (I062/010) [1].")
@needs_libasterix
def export(plots: Path, sensors_file: Path | None, out: Path, category: str,
           sac: int | None, sic: int | None) -> None:
    """Encode timed PLOTS (time, sensor, range or slant_range, bearing) as ASTERIX
    CAT048 target reports with CAT034 north markers and sector crossings; or, with
    --category 062, a TRACKS file as CAT062 system tracks."""
    from mhtrack.io.asterix.api import export_file
    from mhtrack.io.paths import check_output_file
    from mhtrack.io.sensors import read_sensors

    check_output_file(out, inputs=(plots, sensors_file), suffixes=(".pcap", ".ast"),
                      what="recording")
    sensors = read_sensors(sensors_file) if sensors_file is not None else None
    done = export_file(plots, sensors, out, category=category, sac=sac, sic=sic,
                       progress=show_progress())
    say(f"{done.describe()} -> {out}")


COMMANDS = [convert, export]
