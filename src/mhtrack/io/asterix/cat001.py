"""CAT001 monoradar plots and CAT002 service messages (older radars, still in service),
decoded by libasterix (CAT001 edition 1.4, CAT002 1.2) into the columns of CAT048 plots
(:data:`mhtrack.io.asterix.decode.PLOT_COLUMNS` plus ``plot_type``, ``sim``, ``rab``,
``tst``, ``track``; docs/file-formats.md, "ASTERIX recordings").

A CAT001 record is a plot or a track by I001/020 TYP (each record's own UAP: plot first,
then the track UAP when TYP = 1). Its time is I001/141, the time of day truncated to
2¹⁶ × 1/128 s = 512 s. :class:`TimeRestorer` restores the full time of day from a
reference ``r`` — the radar's last CAT002 message (I002/030, full time of day), else its
last restored plot, else the capture time of day — as
``t = r + ((t₁₄₁ − r + 256) mod 512) − 256``, across midnight (:func:`nearest_tod`). It is
exact when ``r`` lies within 192 s of the plot's time (256 s, half the cycle, but the
day's last cycle is only 384 s long: 86 400 = 168 × 512 + 384). A plot with no reference
is counted (``no_time``) and dropped.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix._lib import sub_or_none, uint
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import DAY_S

#: The wrap of I001/141: 2¹⁶ LSBs of 1/128 s.
TRUNC_S = 512.0
NM_M = 1852.0
#: Columns of a CAT001 plot row, in order (PLOT_COLUMNS, then the plot type and flags).
COLUMNS = ("time", "sensor", "sac", "sic", "slant_range", "bearing", "flight_level",
           "mode_3a", "address", "callsign", "track_number", "typ", "plot_type",
           "mode_3a_vg", "flight_level_vg", "sim", "rab", "tst", "track")


def specs() -> tuple[Any, Any]:
    """libasterix's CAT001 edition 1.4 and CAT002 edition 1.2."""
    gen = _lib.modules()[1]
    return gen.Cat_001_1_4, gen.Cat_002_1_2


def _uint(item: Any, name: str) -> int:
    """Subitem ``name`` of ``item`` as an unsigned integer, 0 where it is absent."""
    found = sub_or_none(item, name)
    return 0 if found is None else uint(found)


def record001(bits: Any) -> tuple[Any, Any] | ValueError:
    """One CAT001 record from libasterix ``bits``: by the plot UAP, or the track UAP when
    its I001/020 TYP is 1; ``(record, the bits after it)`` or a ``ValueError``."""
    base = _lib.modules()[0]
    uaps = specs()[0].cv_uap.cv_uaps
    got = uaps["plot"].parse(base.ParsingMode.StrictParsing, bits)
    if isinstance(got, ValueError):
        return got
    i020 = got[0].get_item("020")
    if i020 is not None and _uint(i020, "TYP") == 1:
        return uaps["track"].parse(base.ParsingMode.StrictParsing, bits)
    return got


def records001(raw: bytes) -> list[Any] | ValueError:
    """The records of a CAT001 data block (the octets after its header), each by
    :func:`record001`; a ``ValueError`` when they do not fill the block."""
    bits, out = _lib.modules()[0].Bits.from_bytes(raw), []
    while len(bits):
        got = record001(bits)
        if isinstance(got, ValueError):
            return got
        rec, bits = got
        out.append(rec)
    return out


def plot_row001(rec: Any, at: int, problems: Problems) -> tuple[Any, ...] | None:
    """A CAT001 row with its truncated time of day (s, 0–512) in ``time``, or ``None``
    (counted) without I001/010, 040 or 141."""
    i010, i040, i141 = rec.get_item("010"), rec.get_item("040"), rec.get_item("141")
    if i040 is None:
        problems.add("no_position", at)
        return None
    if i010 is None or i141 is None:
        problems.add("no_time", at)
        return None
    sac, sic = _uint(i010, "SAC"), _uint(i010, "SIC")
    pos = i040.variation
    rho = float(pos.get_item("RHO").variation.content.as_quantity("NM")) * NM_M
    theta = float(pos.get_item("THETA").variation.content.as_quantity("°"))
    i090, i070, i020 = rec.get_item("090"), rec.get_item("070"), rec.get_item("020")
    fl = float(i090.variation.get_item("HGT").variation.content.as_quantity("FL")) \
        if i090 is not None else np.nan
    m3a = i070.variation.get_item("MODE3A").variation.content.as_string() \
        if i070 is not None else ""
    if i020 is None:
        typ = sim = rab = tst = track = -1
    else:
        typ, sim, rab, tst = (_uint(i020, k) for k in ("SSRPSR", "SIM", "RAB", "TST"))
        track = _uint(i020, "TYP")
    ptype = typ if typ >= 0 else 0
    vg = [0 if i is None else 2 * _uint(i, "V") + _uint(i, "G") for i in (i070, i090)]
    i131 = rec.get_item("131")  # received power (dBm): the plot's amplitude
    power = () if i131 is None else \
        (*(np.nan,) * 7, float(i131.variation.content.as_quantity("dBm")))
    return (float(i141.variation.content.as_quantity("s")), sac * 256 + sic, sac, sic,
            rho, theta, fl, m3a, "", "", -1, typ, ptype, *vg, sim, rab, tst, track, *power)


def mark_row002(rec: Any) -> tuple[Any, ...] | None:
    """``(time of day, sensor, kind, azimuth, period)`` of a CAT002 north marker (I002/000
    = 1) or sector crossing (= 2; azimuth from the sector number I002/020, 360/2⁸ °), as
    :func:`mhtrack.io.asterix.decode.mark_row`; ``None`` for other messages or without
    I002/010, 030."""
    i000, i010, i030 = rec.get_item("000"), rec.get_item("010"), rec.get_item("030")
    if i000 is None or i010 is None or i030 is None:
        return None
    kind = uint(i000)
    if kind not in (1, 2):
        return None
    i020, i041 = rec.get_item("020"), rec.get_item("041")
    azimuth = float(i020.variation.content.as_quantity("°")) \
        if i020 is not None and kind == 2 else np.nan
    period = float(i041.variation.content.as_quantity("s")) if i041 is not None else np.nan
    return (float(i030.variation.content.as_quantity("s")),
            _uint(i010, "SAC") * 256 + _uint(i010, "SIC"), kind, azimuth, period)


def records002(raw: bytes) -> list[Any] | ValueError:
    """The records of a CAT002 data block, or a ``ValueError``."""
    base = _lib.modules()[0]
    return specs()[1].cv_uap.parse(base.Bits.from_bytes(raw))


def record002(bits: Any) -> tuple[Any, Any] | ValueError:
    """One CAT002 record from libasterix ``bits``: ``(record, the bits after it)`` or a
    ``ValueError`` (:func:`records002` reads a block of them)."""
    base = _lib.modules()[0]
    return specs()[1].cv_record.parse(base.ParsingMode.StrictParsing, bits)


def nearest_tod(truncated: float, ref: float) -> float:
    """The time of day in [0, 86 400) whose value modulo 512 s is ``truncated`` and which
    is nearest to ``ref`` across midnight (exact when ``ref`` is within 192 s of it):
    ``c = r + ((t₁₄₁ − r + 256) mod 512) − 256`` for ``r`` = ref and ref ∓ 1 day, the
    nearest ``c`` inside the day."""
    best, gap = ref, math.inf
    for r in (ref, ref - DAY_S, ref + DAY_S):
        c = r + (truncated - r + TRUNC_S / 2) % TRUNC_S - TRUNC_S / 2
        if 0.0 <= c < DAY_S and abs(c - r) < gap:
            best, gap = c, abs(c - r)
    return best


class TimeRestorer:
    """Full times of day of CAT001 plots from their truncated I001/141, per radar, in the
    order the reports arrive (streaming: O(radars) memory). Feed each radar's CAT002
    messages with :meth:`mark`; :meth:`restore` each plot."""

    def __init__(self) -> None:
        self.reference: dict[int, float] = {}

    def mark(self, sensor: int, tod: float) -> None:
        """A CAT002 message's full time of day (s) for ``sensor``."""
        if 0.0 <= tod < DAY_S:
            self.reference[sensor] = tod

    def restore(self, sensor: int, truncated: float, capture: float | None,
                at: int, problems: Problems) -> float | None:
        """The plot's full time of day (s), or ``None`` (counted ``no_time``: no reference;
        ``impossible``: truncated time beyond 512 s). ``capture`` is the capture time (POSIX
        s or s of the day), used when the radar has no reference yet."""
        if not 0.0 <= truncated < TRUNC_S:
            problems.add("impossible", at, detail=f"I001/141 {truncated:g} s")
            return None
        ref = self.reference.get(sensor)
        if ref is None:
            if capture is None:
                problems.add("no_time", at, detail="CAT001 plot before any CAT002 "
                             "message of its radar, and no capture time")
                return None
            ref = capture % DAY_S
        t = nearest_tod(truncated, ref)
        self.reference[sensor] = t
        return t


def block001(raw: bytes, at: int, capture: float | None, restorer: TimeRestorer,
             problems: Problems, recs: list[Any] | None = None
             ) -> list[tuple[Any, ...]] | None:
    """The plot rows (:data:`COLUMNS`, full times of day) of one CAT001 data block, or
    ``None`` when its records do not fill it (the caller counts ``undecodable``);
    ``recs``: its records already parsed (:func:`records001`)."""
    recs = records001(raw) if recs is None else recs
    if isinstance(recs, ValueError):
        return None
    out = []
    for rec in recs:
        row = plot_row001(rec, at, problems)
        if row is None:
            continue
        t = restorer.restore(row[1], row[0], capture, at, problems)
        if t is not None:
            out.append((t, *row[1:]))
    return out


def block002(raw: bytes, restorer: TimeRestorer, recs: list[Any] | None = None
             ) -> list[tuple[Any, ...]] | None:
    """The sweep marks of one CAT002 data block (each also a time reference for its
    radar's CAT001 plots), or ``None`` when its records do not fill it; ``recs``: its
    records already parsed (:func:`records002`)."""
    recs = records002(raw) if recs is None else recs
    if isinstance(recs, ValueError):
        return None
    out = []
    for rec in recs:
        i010, i030 = rec.get_item("010"), rec.get_item("030")
        if i010 is not None and i030 is not None:
            restorer.mark(_uint(i010, "SAC") * 256 + _uint(i010, "SIC"),
                          float(i030.variation.content.as_quantity("s")))
        mark = mark_row002(rec)
        if mark is not None:
            out.append(mark)
    return out
