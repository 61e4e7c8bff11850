"""Whether the records of a data block fill it exactly, by any edition of its category
that libasterix carries: the content test that tells a real data block from octets that
only look like one (a category and a length) in a damaged raw stream
(:func:`mhtrack.io.asterix.resync.judged`).

Rule (EUROCONTROL ASTERIX Part 1, §4): a block's records follow one another, each an
FSPEC then the items it announces, with lengths the category's UAP gives, and the last
ends at the block's end. A category with several UAPs (CAT001 plots and tracks, CAT007)
is read record by record, each by the first of its UAPs that parses it. A record whose
FSPEC ends in an octet announcing no item (``00``) is no record: it carries nothing, and
no encoder writes an FSPEC octet it does not need (:func:`announces`) — without this
rule a block's header (category, length) read as records could pass for them.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

import mhtrack.io.asterix._lib as _lib


def announces(raw: bytes, p: int) -> bool:
    """The FSPEC at ``p`` (octets while the FX bit, bit 1, is set) ends inside ``raw``
    in an octet announcing at least one item."""
    n = len(raw)
    while p < n and raw[p] & 1:
        p += 1
    return p < n and raw[p] != 0


@cache
def _editions(cat: int) -> tuple[tuple[Any, ...], ...]:
    """Per edition of ``cat`` (newest first), the record parsers of its UAPs."""
    gen = _lib.modules()[1]
    out = []
    for ed in reversed(gen.manifest["CATS"].get(cat, ())):
        several = getattr(ed.cv_uap, "cv_uaps", None)
        out.append(tuple(several.values()) if several is not None else (ed.cv_record,))
    return tuple(out)


def fills_any_edition(cat: int, raw: bytes) -> bool:
    """``raw`` (a block's octets after its header) is whole records of ``cat`` by one of
    its editions; ``False`` for a category libasterix does not carry."""
    base = _lib.modules()[0]
    return any(_records_fill(parsers, raw, base) for parsers in _editions(cat))


def whole_records(raw: bytes, parse: Callable[[Any], Any]) -> list[Any] | None:
    """The records of ``raw`` (a block's octets after its header) read one after another
    by ``parse`` (libasterix bits -> ``(record, the bits after it)`` or a
    ``ValueError``), each FSPEC announcing an item (:func:`announces`); ``None`` when
    they do not fill ``raw`` exactly."""
    bits, n, out = _lib.modules()[0].Bits.from_bytes(raw), len(raw), []
    while len(bits):
        if not announces(raw, n - len(bits) // 8):
            return None
        got = _parsed(parse, bits)
        if isinstance(got, ValueError):
            return None
        rec, bits = got
        out.append(rec)
    return out


def _records_fill(parsers: tuple[Any, ...], raw: bytes, base: Any) -> bool:
    def first(bits: Any) -> Any:  # each record by the first of the UAPs that parses it
        for parse in parsers:
            got = _parsed(parse.parse, base.ParsingMode.StrictParsing, bits)
            if not isinstance(got, ValueError):
                return got
        return ValueError("no UAP parses the record")

    return whole_records(raw, first) is not None


def _parsed(parse: Any, *args: Any) -> Any:
    """libasterix's result, or a ``ValueError`` for an exception it raises on octets it
    cannot read (some editions' UAPs raise ``TypeError`` on such input)."""
    try:
        return parse(*args)
    except (TypeError, IndexError, KeyError, AttributeError) as e:
        return ValueError(str(e))
