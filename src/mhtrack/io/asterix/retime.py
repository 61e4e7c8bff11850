"""The times of day of ASTERIX data blocks moved on by a whole number of seconds: a
recording replayed again as the same traffic later (``mhtrack replay --loop``,
``docs/live.md``, *Replay*).

Each record's time items are rewritten by libasterix (parse, ``set_item``, unparse; the
other items are the octets they were): I048/140, I034/030, I002/030 and I021/071, 072,
073, 075, 077 (time of day, 1/128 s, 24 bits: ``(raw + 128 · s) mod (86 400 · 128)``,
so the time wraps at midnight as a real feed's does) and I001/141 (the time of day
truncated to 16 bits, 512 s: the full time of day ``t`` restored as the decoder does,
nearest to a time of day given with the datagram — its capture time in a replay —, then
``128 · ((t + s) mod 86 400) mod 2¹⁶``: a day of 86 400 s is no whole number of 512 s,
so adding to the truncated value alone would be wrong after midnight). A whole number
of seconds keeps every fraction of a second as it was, with I021/074 and 076 (the
fractions of 073 and 075) left alone. Blocks of other categories are sent unchanged; a
block of one of these categories that libasterix cannot parse, or whose records do not
fill it, is sent unchanged too and counted (:func:`time_layout`).
"""

from __future__ import annotations

from functools import cache
from typing import Any

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix import cat001, cat021
from mhtrack.io.asterix.container import blocks
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import DAY_S

#: Raw units per second of a time-of-day item (LSB 1/128 s).
PER_S = 128
#: Rewritten items per category, each with the modulus of its raw value.
_DAY, _TRUNC = int(DAY_S) * PER_S, 1 << 16
TIME_ITEMS: dict[int, tuple[tuple[str, int], ...]] = {
    48: (("140", _DAY),),
    34: (("030", _DAY),),
    2: (("030", _DAY),),
    1: (("141", _TRUNC),),
    21: tuple((name, _DAY) for name in ("071", "072", "073", "075", "077")),
}


@cache
def _uap(cat: int) -> Any:
    return {48: _lib.cat048, 34: _lib.cat034, 2: lambda: cat001.specs()[1],
            21: cat021.spec}[cat]().cv_uap


def _records(cat: int, raw: bytes) -> list[Any] | ValueError:
    """The records of one data block as the decoder parses them (CAT001: the plot or
    the track UAP by I001/020)."""
    if cat == 1:
        return cat001.records001(raw)
    return _uap(cat).parse(_lib.modules()[0].Bits.from_bytes(raw))


def _width(modulus: int) -> int:
    return (modulus - 1).bit_length()


def time_fields(payload: bytes) -> tuple[tuple[int, int, int], ...]:
    """``(byte offset, octets, modulus)`` of every time item in ``payload`` (module
    docstring), found with libasterix: each record is unparsed with the item as it is
    and with all its bits flipped; the octets that differ are the item's."""
    return time_layout(payload)[0]


def time_layout(payload: bytes) -> tuple[tuple[tuple[int, int, int], ...], int]:
    """:func:`time_fields` of ``payload`` and the number of its blocks of a retimed
    category left unmoved (unparsable, or records not filling the block)."""
    found: list[tuple[int, int, int]] = []
    unmoved = 0
    for at, cat, raw in blocks(payload, 0, Problems()):
        items = TIME_ITEMS.get(cat)
        if items is None:
            continue
        records = _records(cat, raw)
        if isinstance(records, ValueError) or not records:
            unmoved += 1
            continue
        pos, mine = at + 3, []
        for rec in records:
            octets = rec.unparse().to_bytes()
            for name, modulus in items:
                item = rec.get_item(name)
                if item is None:
                    continue
                raw_value = int(item.variation.content.as_uint())
                flipped = rec.set_item(name, raw_value ^ ((1 << _width(modulus)) - 1))
                other = flipped.unparse().to_bytes()
                diff = [i for i, (a, b) in enumerate(zip(octets, other, strict=True))
                        if a != b]
                mine.append((pos + diff[0], diff[-1] - diff[0] + 1, modulus))
            pos += len(octets)
        if pos == at + 3 + len(raw):  # the records fill the block: else left alone
            found.extend(mine)
        else:
            unmoved += 1
    return tuple(found), unmoved


def patch_times(payload: bytes, fields: tuple[tuple[int, int, int], ...],
                seconds: int, near: float | None = None) -> bytes:
    """``payload`` with the time items at ``fields`` (:func:`time_fields`) moved on by
    ``seconds`` (a whole number); ``near``: a time of day within 192 s of the payload's
    (s), needed for a truncated time (module docstring)."""
    if seconds != int(seconds):
        raise ValueError(f"the shift must be a whole number of seconds, got {seconds!r}")
    if not seconds or not fields:
        return payload
    add, out = int(seconds) * PER_S, bytearray(payload)
    for pos, n, modulus in fields:
        raw = int.from_bytes(out[pos:pos + n], "big")
        if modulus == _TRUNC:  # the full time of day first (module docstring)
            if near is None:
                raise ValueError("a truncated time of day (I001/141) needs the time "
                                 "of day it is near")
            full = round(cat001.nearest_tod(raw / PER_S, near % DAY_S) * PER_S)
            value = (full + add) % _DAY % _TRUNC
        else:
            value = (raw + add) % modulus
        out[pos:pos + n] = value.to_bytes(n, "big")
    return bytes(out)


def shift_times(payload: bytes, seconds: int, near: float | None = None) -> bytes:
    """``payload`` (one or more data blocks) with every time item moved on by
    ``seconds`` (a whole number; ``near`` as :func:`patch_times`; module docstring)."""
    return patch_times(payload, time_fields(payload), seconds, near)
