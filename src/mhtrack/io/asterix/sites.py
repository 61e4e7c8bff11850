"""The radars of a recording from the data: sites sent in CAT034 (I034/120) fill a sensors
file that lacks them, or stand in for a missing sensors file (docs/file-formats.md,
"ASTERIX recordings").

For each radar whose plots a recording holds:

* listed in the sensors file: the file's entry is used; where the radar also sent its
  site in I034/120 and the two are more than :data:`DISAGREE_M` apart (geodesic distance
  on WGS-84), one warning line says so (the file wins); an entry without a site (a polar
  radar with its errors only) takes the I034/120 site (and height, unless it gives
  ``alt``);
* not listed, or no sensors file, but its I034/120 was received: a polar radar at that
  site (height from I034/120) with the errors and detection probability of
  :data:`DEFAULT_RADAR` (below) and the radar's own period from its CAT034 messages;
* no site at all: skipped, the radars listed in one warning line;
* an ADS-B station (CAT021) the file does not list: a sensor of kind ``adsb``
  (:data:`DEFAULT_ADSB`); its reports carry their own positions and accuracies.

The local frame is the file's (its origin, else its first lat/lon site) or, without a
sensors file, centred on the first radar's site (the lowest id), else on the first
ADS-B report.

:data:`DEFAULT_RADAR`, the figures a secondary radar should meet: EUROCONTROL Standard
Document for Radar Surveillance in En-Route Airspace and Major Terminal Areas,
SUR.ET1.ST01.1000-STD-01-01, Edition 1.0 (Released Issue), March 1997, chapter 6 (SSR
requirements §6.3, Recommendations in the document's terms, §6.3.1):

* ``pd`` 0.97 — §6.3.2.1, "Overall probability of detection: > 97 %" (checked against a
  verbatim quotation of the document; its PSR counterpart, §6.4.2.1, is > 90 %);
* ``sigma_range`` 70 m and ``sigma_bearing_deg`` 0.08° — the SSR random errors (standard
  deviations of slant range and azimuth) of §6.3.3. These two were **not** found in the
  text that could be consulted here (the stored copies hold the document's front pages
  and its PSR figures, §6.4.3.1: random σ 120 m in slant range and 0.15° in azimuth,
  systematic 100 m, 0.1°, 1 m/NM, 100 ms); they are kept, marked unverified, and a
  sensors file entry overrides them. Being bounds a compliant radar should meet, they
  overstate the errors of a good monopulse SSR, never understate them. A second search
  of the stored pages and documentation (issue 29, SSR/PSR accuracy, ESASSP, the 1997
  standard and its companion "Radar Sensor Performance Analysis",
  SUR.ET1.ST03.1000-STD-01-01) again found the documents' front pages only: the two
  values stay marked unverified. A radar's plot types may have their own σ and ``P_D``
  in the sensors file (PSR, SSR, combined, Mode S; docs/file-formats.md).

The successor in substance, the EUROCONTROL Specification for ATM Surveillance System
Performance (ESASSP, EUROCONTROL-SPEC-0147, Edition 1.1 2015 / 1.2 2021), states
requirements on the whole surveillance chain (horizontal position RMS error,
probability of update) for 3 NM and 5 NM separation, not per-radar σ, so it gives no
figure for this default.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import replace

from mhtrack.models.radars import RadarSensor, SensorSet

#: A sensors file's site and the radar's own I034/120 differ by more than this (m): warn.
DISAGREE_M = 100.0
#: Errors of a radar known only from its CAT034 site: SUR.ET1.ST01.1000-STD-01-01 (1997)
#: §6.3.2.1 (pd) and §6.3.3 (σ, unverified here; module docstring).
DEFAULT_RADAR = {"pd": 0.97, "sigma_range": 70.0, "sigma_bearing_deg": 0.08}
#: An ADS-B station the sensors file does not list: its reports' σ come from their
#: NACp/NUCp (:mod:`~mhtrack.io.asterix.cat021`); ``pd`` is an assumption (a station that
#: receives most of an aircraft's position squitters) — give it in the sensors file.
DEFAULT_ADSB = {"pd": 0.95}

#: ``sensor -> (lat deg, lon deg, height m, byte offset)`` as the decoder gathers them.
Sites = dict[int, tuple[float, float, float, int]]


def radar_name(sensor: int) -> str:
    """``6412 (SAC 25, SIC 12)``."""
    return f"{sensor} (SAC {sensor >> 8}, SIC {sensor & 0xFF})"


def sensors_with_sites(given: SensorSet | None, sites: Sites, radars: Sequence[int],
                       name: str, *, warn: bool = True, adsb: Sequence[int] = (),
                       first_position: tuple[float, float] | None = None
                       ) -> tuple[SensorSet | None, list[int]]:
    """The sensors to convert the plots of ``radars`` and the reports of the ADS-B
    stations ``adsb`` with, and the radars skipped (no site known). ``given`` (the
    sensors file, or ``None``) wins; radars it lacks are added from ``sites``
    (I034/120), ADS-B stations as sensors of kind ``adsb`` (:data:`DEFAULT_ADSB`). With
    ``warn``, one warning line per site that disagrees with the file by more than
    :data:`DISAGREE_M` (naming ``name`` and the byte of the I034/120). A set with no
    geodetic reference is centred on ``first_position`` (the first ADS-B report).
    ``None`` when no sensor is known."""
    known = {s.id: s for s in given.sensors} if given is not None else {}
    added: list[RadarSensor] = [RadarSensor(a, "adsb", **DEFAULT_ADSB)  # type: ignore[arg-type]
                                for a in sorted(set(adsb)) if a not in known]
    skipped: list[int] = []
    filled: dict[int, RadarSensor] = {}
    for sid in sorted(set(radars)):
        if sid in known and known[sid].kind == "polar" and not known[sid].has_site:
            if sid in sites:  # the file gives the errors, the radar its site
                lat, lon, hgt, _ = sites[sid]
                s = known[sid]
                filled[sid] = replace(s, lat=lat, lon=lon, alt=hgt if s.alt is None else s.alt)
            else:
                skipped.append(sid)
            continue
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
    if not added and not filled:
        return given, skipped
    out = SensorSet(None, tuple(added)) if given is None else replace(
        given, sensors=(*(filled.get(s.id, s) for s in given.sensors), *added))
    if out.reference is None and first_position is not None:
        out = replace(out, origin=first_position)
    return out, skipped


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
