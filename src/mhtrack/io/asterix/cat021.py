"""CAT021 ADS-B target reports, decoded by libasterix (edition 2.6), as the reports of a
sensor of kind ``adsb``: WGS-84 position with its reported accuracy as a standard deviation
(docs/file-formats.md, "ASTERIX recordings").

Position: I021/131 (high resolution, 180/2³⁰ °), else I021/130 (180/2²³ °). Time: I021/071
(time of applicability for position), else 073 (time of message reception for position),
else 077 (time of report transmission), s of the day. Reports with |lat| > 90°,
|lon| > 180° or a time of day ≥ 86 400 s are physically impossible: refused and counted
(``impossible``), never passed on.

Accuracy, from I021/090. With a MOPS version (I021/210 VN) of 1 (DO-260A) or 2 (DO-260B),
or without I021/210 when NACp is sent: the Navigation Accuracy Category for Position NACp,
whose Estimated Position Uncertainty EPU bounds the horizontal error with 95 % probability
(RTCA DO-260B, §2.2.3.2.7.2.7, table of NACp): 11 < 3 m, 10 < 10 m, 9 < 30 m, 8 < 0.05 NM,
7 < 0.1 NM, 6 < 0.3 NM, 5 < 0.5 NM, 4 < 1 NM, 3 < 2 NM, 2 < 4 NM, 1 < 10 NM, 0 unknown.
With VN 0 (DO-260): the Navigation Uncertainty Category NUCp, whose HFOM is the 95 %
horizontal accuracy bound (RTCA DO-260, NUCp table): 9 < 3 m, 8 < 10 m, 7 < 0.05 NM,
6 < 0.1 NM, 5 < 0.25 NM, 4 < 0.5 NM, 3 < 1 NM, 2 < 5 NM, 1 < 10 NM, 0 unknown.
(Both tables as summarised in Airbus, "Getting to grips with surveillance", appendix E,
and RTCA DO-242A's NUCp/NACp definitions: HFOM = EPU, the 95 % horizontal radius.)
The bound R is taken as the 95 % radius of a circular Gaussian: P(r < R) = 1 − exp(−R²/2σ²)
= 0.95, so σ = R / √(−2 ln 0.05) = R / 2.4477 per axis. Category 0 (unknown) gives NaN.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix._lib import quantity, sub_or_none, uint
from mhtrack.io.asterix.notplots import PLOT_TYPES
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import DAY_S

NM_M = 1852.0
#: σ per axis of a circular Gaussian whose 95 % radius is R: R / √(−2 ln 0.05).
R95_TO_SIGMA = 1.0 / math.sqrt(-2.0 * math.log(0.05))
#: NACp → EPU (m, 95 %), DO-260B.
NACP_EPU_M = {11: 3.0, 10: 10.0, 9: 30.0, 8: 0.05 * NM_M, 7: 0.1 * NM_M, 6: 0.3 * NM_M,
              5: 0.5 * NM_M, 4: 1.0 * NM_M, 3: 2.0 * NM_M, 2: 4.0 * NM_M, 1: 10.0 * NM_M}
#: NUCp → HFOM (m, 95 %), DO-260.
NUCP_HFOM_M = {9: 3.0, 8: 10.0, 7: 0.05 * NM_M, 6: 0.1 * NM_M, 5: 0.25 * NM_M,
               4: 0.5 * NM_M, 3: 1.0 * NM_M, 2: 5.0 * NM_M, 1: 10.0 * NM_M}
ADSB = next(k for k, v in PLOT_TYPES.items() if v == "adsb")
#: Columns of an ADS-B row: PLOT_COLUMNS' identity and time columns, the position in
#: WGS-84 (``slant_range``/``bearing`` NaN: no radar), its σ (m), the plot type and flags.
COLUMNS = ("time", "sensor", "sac", "sic", "slant_range", "bearing", "flight_level",
           "mode_3a", "address", "callsign", "track_number", "typ", "plot_type",
           "mode_3a_vg", "flight_level_vg", "sim", "rab", "tst", "lat", "lon", "sigma")


def spec() -> Any:
    """libasterix's CAT021 edition 2.6."""
    return _lib.modules()[1].Cat_021_2_6


def sigma_m(nacp: int, nucp: int, version: int) -> float:
    """σ (m per axis) of a report's position from its NACp (``version`` ≥ 1 or −1
    unknown, NACp ≥ 0) or NUCp (``version`` 0, or no NACp); NaN when unknown."""
    if version != 0 and nacp > 0:
        return NACP_EPU_M.get(nacp, math.nan) * R95_TO_SIGMA
    if (version == 0 or nacp < 0) and nucp > 0:
        return NUCP_HFOM_M.get(nucp, math.nan) * R95_TO_SIGMA
    return math.nan



def _first(rec: Any, *names: str) -> Any:
    for name in names:
        if (item := rec.get_item(name)) is not None:
            return item
    return None




def report_row(rec: Any, at: int, problems: Problems) -> tuple[Any, ...] | None:
    """One ADS-B row (:data:`COLUMNS`) of a CAT021 record, or ``None``: without I021/010,
    a position or a time (``no_position``/``no_time``), or impossible (``impossible``)."""
    i010 = rec.get_item("010")
    pos = _first(rec, "131", "130")
    tod_item = _first(rec, "071", "073", "077")
    if pos is None:
        problems.add("no_position", at)
        return None
    if i010 is None or tod_item is None:
        problems.add("no_time", at)
        return None
    lat, lon = quantity(sub_or_none(pos, "LAT"), "°"), quantity(sub_or_none(pos, "LON"), "°")
    tod = quantity(tod_item, "s")
    if abs(lat) > 90.0 or abs(lon) > 180.0 or not 0.0 <= tod < DAY_S:
        problems.add("impossible", at, detail=f"CAT021 lat {lat:g}, lon {lon:g}, "
                     f"time {tod:g} s")
        return None
    sac, sic = uint(sub_or_none(i010, "SAC")), uint(sub_or_none(i010, "SIC"))
    i090, i210 = rec.get_item("090"), rec.get_item("210")
    nacp = nucp = version = -1
    if i090 is not None:
        nucp = uint(sub_or_none(i090, "NUCPNIC"))
        if (n := sub_or_none(i090, "NACP")) is not None:
            nacp = uint(n)
    if i210 is not None and (vn := sub_or_none(i210, "VN")) is not None:
        version = uint(vn)
    i145, i080, i170 = rec.get_item("145"), rec.get_item("080"), rec.get_item("170")
    i161, i040 = rec.get_item("161"), rec.get_item("040")
    fl = quantity(i145, "FL") if i145 is not None else np.nan
    address = f"{uint(i080):06X}" if i080 is not None else ""
    callsign = i170.variation.content.as_string().strip() if i170 is not None else ""
    tn = uint(sub_or_none(i161, "TRNUM")) if i161 is not None else -1
    flags = [-1, -1, -1]
    if i040 is not None:
        flags = [uint(x) if (x := sub_or_none(i040, k)) is not None else 0
                 for k in ("SIM", "RAB", "TST")]
    return (tod, sac * 256 + sic, sac, sic, np.nan, np.nan, fl, "", address, callsign, tn,
            -1, ADSB, 0, 0, *flags, lat, lon, sigma_m(nacp, nucp, version))


def record021(bits: Any) -> tuple[Any, Any] | ValueError:
    """One CAT021 record (:func:`spec`) from libasterix ``bits``: ``(record, the bits
    after it)`` or a ``ValueError``."""
    return spec().cv_record.parse(_lib.modules()[0].ParsingMode.StrictParsing, bits)


def block021(raw: bytes, at: int, problems: Problems, recs: list[Any] | None = None
             ) -> list[tuple[Any, ...]] | None:
    """The ADS-B rows of one CAT021 data block, or ``None`` when its records do not fill
    it (the caller counts ``undecodable``); ``recs``: its records already parsed."""
    if recs is None:
        recs = spec().cv_uap.parse(_lib.modules()[0].Bits.from_bytes(raw))
    if isinstance(recs, ValueError):
        return None
    return [r for r in (report_row(rec, at, problems) for rec in recs) if r is not None]
