"""CAT001 plots, CAT002 sweep marks and CAT021 ADS-B reports encoded by libasterix, for
test recordings and for other tools (the items :mod:`~mhtrack.io.asterix.cat001` and
:mod:`~mhtrack.io.asterix.cat021` read). Values are rounded to their item's LSB; one data
block per run of one radar's messages of one category, at most :data:`MAX_RECORDS`.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from mhtrack.io.asterix.cat001 import specs
from mhtrack.io.asterix.cat021 import spec as spec021

MAX_RECORDS = 40
NM_M = 1852.0


def _sid(sensor: int) -> tuple[tuple[str, int], tuple[str, int]]:
    return ("SAC", sensor >> 8), ("SIC", sensor & 0xFF)


def plot001(time: float, sensor: int, slant: float, bearing: float, *, typ: int = 3,
            fl: float = float("nan"), mode_3a: str = "", sim: int = 0, rab: int = 0,
            tst: int = 0) -> Any:
    """A CAT001 plot record (I001/141 the time of day truncated to 512 s, 1/128 s;
    I001/040 1/128 NM and 360/2¹⁶ °)."""
    plot = specs()[0].cv_uap.cv_uaps["plot"]
    items: dict[str, Any] = {
        "010": _sid(sensor),
        "020": ((0, ("SIM", sim), ("SSRPSR", typ), 0, 0, ("RAB", rab), None),
                (("TST", tst), 0, 0, 0, 0, None)),
        "040": (("RHO", round(slant / NM_M * 128)),
                ("THETA", round(bearing / 360.0 * 65536) % 65536)),
        "141": round(time % 86400.0 * 128) % 65536,
    }
    if mode_3a:
        items["070"] = (0, 0, 0, 0, ("MODE3A", mode_3a))
    if not np.isnan(fl):
        items["090"] = (0, 0, ("HGT", round(fl * 4) & 0x3FFF))
    return plot.create(items)


def mark002(time: float, sensor: int, kind: int, azimuth: float = 0.0,
            period: float | None = None) -> Any:
    """A CAT002 north marker (``kind`` 1) or sector crossing (2, sector 360/2⁸ °)."""
    items: dict[str, Any] = {"000": kind, "010": _sid(sensor),
                             "030": round(time % 86400.0 * 128) % (86400 * 128)}
    if kind == 2:
        items["020"] = round(azimuth / 360.0 * 256) % 256
    if period is not None:
        items["041"] = round(period * 128)
    return specs()[1].cv_record.create(items)


def report021(time: float, sensor: int, lat: float, lon: float, *, nacp: int = 9,
              nucp: int = 0, version: int = 2, fl: float = float("nan"),
              address: str = "", callsign: str = "", track_number: int = -1,
              sim: int = 0, rab: int = 0, tst: int = 0) -> Any:
    """A CAT021 report: I021/131 (180/2³⁰ °), 071 (1/128 s), 090 NUCp and NACp, 210 VN."""
    step = 180.0 / 2**30
    items: dict[str, Any] = {
        "010": _sid(sensor),
        "040": ((0, 0, 0, ("RAB", rab), None),
                (0, 0, ("SIM", sim), ("TST", tst), 0, 0, None)),
        "071": round(time % 86400.0 * 128) % (86400 * 128),
        "131": (("LAT", round(lat / step)), ("LON", round(lon / step))),
        "090": ((0, ("NUCPNIC", nucp), None), (0, 0, ("NACP", nacp), None)),
        "210": (0, ("VNS", 0), ("VN", version), ("LTT", 2)),
    }
    if not np.isnan(fl):
        items["145"] = round(fl * 4) & 0xFFFF
    if address:
        items["080"] = int(address, 16)
    if callsign:
        items["170"] = callsign.ljust(8)[:8]
    if track_number >= 0:
        items["161"] = (0, ("TRNUM", track_number))
    return spec021().cv_record.create(items)


def blocks(messages: Iterable[tuple[float, int, int, Any]]
           ) -> list[tuple[float, int, bytes]]:
    """``(time, sensor, data block)`` of ``(time, sensor, category, record)`` messages in
    time order (stable), runs of one radar and category per block."""
    cats = {1: specs()[0], 2: specs()[1], 21: spec021()}
    out: list[tuple[float, int, bytes]] = []
    run: list[tuple[float, int, int, Any]] = []

    def flush() -> None:
        block = cats[run[0][2]].create([m[3] for m in run]).unparse().to_bytes()
        out.append((run[0][0], run[0][1], block))

    for m in sorted(messages, key=lambda m: m[0]):
        if run and (m[1] != run[0][1] or m[2] != run[0][2] or len(run) >= MAX_RECORDS):
            flush()
            run = []
        run.append(m)
    if run:
        flush()
    return out
