"""CAT062 records of track rows with attributes, encoded with NumPy: the octets
libasterix writes for the items of :func:`~mhtrack.io.asterix.cat062_items.attribute_items`
(EUROCONTROL ASTERIX CAT062 edition 1.18), each item only on the rows that have it.

Items in FRN order (:mod:`.octets` for FSPEC, compound items and byte order): 010 (1),
070 (4), 105 (5), 185 (7), 060 (9: V, G, CH 0, spare, the 12-bit code), 245 (10: STI 0
in the top two bits of one octet, then the callsign as eight 6-bit characters), 380 (11,
compound: ADR 3 octets, ID the callsign's 6 octets), 040 (12), 080 (13: four octets,
CNF and CST as :mod:`.cat062_fast`), 290 (14, compound: PSR, SSR, MDS one octet each,
subfields 2–4), 136 (17, 2 octets), 220 (20, 2 octets), 500 (27, compound: APC X, Y 2
octets each, COV 2 octets) and 340 (28, compound: SID 2 octets, POS RHO, THETA 2 each,
MDC V, G and the level in 14 bits, MDA V, G, L 0, spare and the code, TYP its type in
the top three bits). The 6-bit character of A–Z, 0–9 and space is its ASCII code's low
six bits (ICAO Annex 10).

Not covered (:func:`covered` false; the caller then encodes with libasterix, whose
answer, an encoding or a refusal, stands): codes beyond 12 bits, addresses beyond 24
bits, V/G pairs beyond 0–3, negative measured ranges.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.attributes import TrackAttributes
from mhtrack.io.asterix.cat062_items import TYP340
from mhtrack.io.asterix.octets import Segment, big_endian, compound, fspec


def covered(a: TrackAttributes, v: dict[str, Any]) -> bool:
    """Every row's attributes are encoded here (module docstring); ``v`` their
    :func:`~mhtrack.io.asterix.cat062_items.attribute_raw`."""
    sid = a.meas_sensor >= 0
    return bool(np.all(a.mode_3a <= 0o7777) and np.all(a.address <= 0xFFFFFF)
                and np.all(~sid | (a.meas_mode_3a <= 0o7777))
                and np.all(~(sid & (a.meas_mode_3a >= 0))
                           | ((a.meas_mode_3a_vg >= 0) & (a.meas_mode_3a_vg <= 3)))
                and np.all(~(sid & np.isfinite(a.meas_flight_level))
                           | ((a.meas_flight_level_vg >= 0) & (a.meas_flight_level_vg <= 3)))
                and np.all(~(sid & v["pos"]) | (v["rho"] >= 0)))


def callsign_octets(names: list[str]) -> np.ndarray:
    """``(n, 6)`` octets of callsigns (A–Z, 0–9, space; at most 8, padded with spaces)
    as eight 6-bit characters."""
    n = len(names)
    text = np.array([s.ljust(8) for s in names], "S8").view(np.uint8).reshape(n, 8)
    six = (text & 0x3F).astype(np.int64)
    return big_endian((six << np.arange(42, -1, -6, dtype=np.int64)).sum(axis=1), 6, n)


def record_segments(core: dict[str, Any], tentative: np.ndarray, coasting: np.ndarray,
                    a: TrackAttributes, v: dict[str, Any]) -> list[Segment]:
    """The segments (:mod:`.octets`) of the rows' records: ``core`` the raw values of
    :func:`~mhtrack.io.asterix.cat062.core_raw`, ``v`` of
    :func:`~mhtrack.io.asterix.cat062_items.attribute_raw` (module docstring)."""
    n = len(core["tod"])
    every = np.ones(n, bool)

    def f(value: Any, size: int) -> np.ndarray:
        return big_endian(value, size, n)

    status = np.concatenate([f(0x01 | (np.asarray(tentative) != 0) << 1, 1), f(1, 1),
                             f(1, 1), f(np.asarray(coasting) != 0, 1) << 7], axis=1)
    named = np.array([s != "" for s in v["names"]], bool)
    chars = callsign_octets(v["names"])
    sid = a.meas_sensor >= 0
    typ = np.zeros(n, np.int64)
    for ours, code in TYP340.items():
        typ[a.meas_type == ours] = code
    vg_a, vg_c = a.meas_mode_3a_vg, a.meas_flight_level_vg
    items: dict[int, list[Segment]] = {
        1: [(every, f((core["sac"] << 8) | core["sic"], 2))],
        4: [(every, f(core["tod"], 3))],
        5: [(every, np.concatenate([f(core["lat"], 4), f(core["lon"], 4)], axis=1))],
        7: [(every, np.concatenate([f(core["vx"], 2), f(core["vy"], 2)], axis=1))],
        9: [(a.mode_3a >= 0, f(a.mode_3a, 2))],
        10: [(named, np.concatenate([f(0, 1), chars], axis=1))],
        11: compound({1: (a.address >= 0, f(a.address, 3)), 2: (named, chars)}, n),
        12: [(every, f(core["track"], 2))],
        13: [(every, status)],
        14: compound({k: (has, f(age, 1)) for k, (has, age) in
                      zip((2, 3, 4), v["ages"].values(), strict=True)}, n),
        17: [(np.isfinite(a.flight_level), f(v["fl"], 2))],
        20: [(np.isfinite(a.rate_of_climb), f(v["roc"], 2))],
        27: compound({1: (v["known"], np.concatenate([f(v["ax"], 2), f(v["ay"], 2)], 1)),
                      2: (v["known"], f(v["cov"], 2))}, n),
        28: compound({
            1: (sid, f(a.meas_sensor, 2)),
            2: (sid & v["pos"], np.concatenate([f(v["rho"], 2), f(v["theta"], 2)], 1)),
            4: (sid & np.isfinite(a.meas_flight_level),
                f((vg_c << 14) | (v["mfl"] & 0x3FFF), 2)),
            5: (sid & (a.meas_mode_3a >= 0), f((vg_a << 14) | (a.meas_mode_3a & 0xFFF), 2)),
            6: (sid & (typ > 0), f(typ << 5, 1))}, n),
    }
    present = {frn: np.logical_or.reduce([p for p, _ in segs]) for frn, segs in items.items()}
    out = fspec(present, n)
    for frn in sorted(items):
        out += items[frn]
    return out
