"""Decoded plots in the tracker's local frame: ADS-B reports (CAT021) from their WGS-84
position with σ per axis from NACp/NUCp (or the sensors file's ``sigma``), radar plots
(CAT048/CAT001) from slant range and bearing — ground range
(:func:`~mhtrack.io.asterix.api.ground_ranges`) then
:func:`~mhtrack.io.timed_plots.polar_plots` with each plot type's σ — as
``mhtrack convert`` + ``mhtrack track`` do. Every sensor must be what its reports say it
is (:func:`check_radars`)."""

from __future__ import annotations

import numpy as np

from mhtrack.errors import InputError
from mhtrack.io.asterix.api import ground_ranges
from mhtrack.io.timed_plots import polar_plots
from mhtrack.models.radars import SensorSet


def check_radars(sensors: SensorSet, sensor: np.ndarray, offset: np.ndarray,
                 adsb: np.ndarray, name: str) -> None:
    """Every radar kept is a polar sensor with a lat/lon site, every ADS-B station a
    sensor of kind ``adsb`` (else an :class:`InputError` naming ``name`` and the byte of
    its first report)."""
    for sid in np.unique(sensor).tolist():
        s = sensors.sensor(sid)
        mine = sensor == sid
        at = int(offset[mine][0])
        if adsb[mine].any() and s.kind != "adsb":
            raise InputError(f"{name}, byte {at}: sensor {sid} sends ADS-B "
                             f"reports (CAT021) but the sensors file makes it "
                             f"{s.kind!r}: give it kind = \"adsb\"", file=name)
        if not adsb[mine].all() and (s.kind != "polar" or s.lat is None):
            raise InputError(f"{name}, byte {at}: sensor {sid} of the sensors file "
                             "is not a polar radar with a lat/lon site (its ASTERIX "
                             "plots are range and bearing)", file=name)


def local_positions(sensors: SensorSet, p: dict[str, np.ndarray], adsb: np.ndarray,
                    name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``x, y, R`` of decoded plots ``p`` (columns ``sensor``, ``offset``, ``lat``,
    ``lon``, ``sigma``, ``slant_range``, ``bearing``, ``flight_level``, optional
    ``plot_type``; ``adsb`` marks the ADS-B reports), after :func:`check_radars`."""
    sensor = p["sensor"]
    check_radars(sensors, sensor, p["offset"], adsb, name)
    x, y, R = np.empty(sensor.size), np.empty(sensor.size), np.zeros((sensor.size, 2, 2))
    if adsb.any():  # WGS-84 positions, σ per axis from NACp/NUCp
        x[adsb], y[adsb] = sensors.frame().to_local(p["lat"][adsb], p["lon"][adsb])
        R[adsb, 0, 0] = R[adsb, 1, 1] = p["sigma"][adsb] ** 2
    polar = ~adsb
    types = p.get("plot_type")
    rng = ground_ranges(sensors, sensor[polar], p["slant_range"][polar],
                        p["bearing"][polar], p["flight_level"][polar])
    for sid in np.unique(sensor[polar]).tolist():
        mine = sensor == sid
        x[mine], y[mine], R[mine] = polar_plots(sensors, sid, rng[sensor[polar] == sid],
                                                p["bearing"][mine],
                                                types[mine] if types is not None else None)
    return x, y, R
