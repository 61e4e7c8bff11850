"""The radars of a recording from the data: sites sent in CAT034 (I034/120) fill a sensors
file that lacks them, or stand in for a missing sensors file (docs/file-formats.md,
"ASTERIX recordings").

For each radar whose plots a recording holds:

* listed in the sensors file: the file's entry is used; where the radar also sent its
  site in I034/120 and the two are more than :data:`DISAGREE_M` apart (geodesic distance
  on WGS-84), one warning line says so (the file wins);
* not listed, or no sensors file, but its I034/120 was received: a polar radar at that
  site (height from I034/120) with the errors and detection probability of
  :data:`DEFAULT_RADAR` — the EUROCONTROL Standard for Radar Surveillance in En-Route
  Airspace and Major Terminal Areas (SUR.ET1.ST01.1000-STD-01-01, 1997), SSR
  performance requirements: random range error σ ≤ 70 m, azimuth σ ≤ 0.08°, detection
  probability ≥ 97 % — the radar's own period from its CAT034 messages;
* no site at all: skipped, the radars listed in one warning line.

The local frame is the file's (its origin, else its first lat/lon site) or, without a
sensors file, centred on the first radar's site (the lowest id).
"""

from __future__ import annotations

import logging
from dataclasses import replace

from mhtrack.models.radars import RadarSensor, SensorSet

#: A sensors file's site and the radar's own I034/120 differ by more than this (m): warn.
DISAGREE_M = 100.0
#: Errors of a radar known only from its CAT034 site (module docstring).
DEFAULT_RADAR = {"pd": 0.97, "sigma_range": 70.0, "sigma_bearing_deg": 0.08}

#: ``sensor -> (lat deg, lon deg, height m, byte offset)`` as the decoder gathers them.
Sites = dict[int, tuple[float, float, float, int]]


def radar_name(sensor: int) -> str:
    """``6412 (SAC 25, SIC 12)``."""
    return f"{sensor} (SAC {sensor >> 8}, SIC {sensor & 0xFF})"


def sensors_with_sites(given: SensorSet | None, sites: Sites, radars: list[int] | tuple[int, ...],
                       name: str, *, warn: bool = True
                       ) -> tuple[SensorSet | None, list[int]]:
    """The sensors to convert the plots of ``radars`` with, and the radars skipped (no
    site known). ``given`` (the sensors file, or ``None``) wins; radars it lacks are
    added from ``sites`` (I034/120). With ``warn``, one warning line per site that
    disagrees with the file by more than :data:`DISAGREE_M` (naming ``name`` and the
    byte of the I034/120). ``None`` when no radar has a site."""
    known = {s.id: s for s in given.sensors} if given is not None else {}
    added: list[RadarSensor] = []
    skipped: list[int] = []
    for sid in sorted(set(radars)):
        if sid in known:
            s = known[sid]
            if warn and sid in sites and s.lat is not None:
                lat, lon, _, at = sites[sid]
                d = _distance(s.lat, s.lon, lat, lon)  # type: ignore[arg-type]
                if d > DISAGREE_M:
                    logging.getLogger("mhtrack").warning(
                        "%s, byte %d: radar %s sends its site (I034/120) at %.6f, %.6f, "
                        "%.0f m from the sensors file's %.6f, %.6f: the sensors file's is "
                        "used", name, at, radar_name(sid), lat, lon, d, s.lat, s.lon)
            continue
        if sid in sites:
            lat, lon, hgt, _ = sites[sid]
            added.append(RadarSensor(sid, "polar", lat=lat, lon=lon, alt=hgt,
                                     **DEFAULT_RADAR))  # type: ignore[arg-type]
        else:
            skipped.append(sid)
    if given is None:
        return (SensorSet(None, tuple(added)) if added else None), skipped
    return (replace(given, sensors=(*given.sensors, *added)) if added else given), skipped


def skipped_line(name: str, skipped: list[int], n_plots: int, first: int) -> str:
    """The one warning line of radars skipped for want of a site."""
    return (f"{name}: {len(skipped)} radar(s) without a known site skipped, {n_plots} plots "
            f"(first at byte {first}): {', '.join(radar_name(s) for s in skipped)} — not in "
            "the sensors file and no I034/120 received; add them to the sensors file "
            "(id = SAC·256 + SIC, lat, lon) to track them")


def _distance(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Geodesic distance (m) on WGS-84 (pyproj)."""
    from pyproj import Geod

    return float(Geod(ellps="WGS84").inv(lon1, lat1, lon2, lat2)[2])
