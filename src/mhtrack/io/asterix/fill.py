"""Whether the records of a data block fill it exactly, by any edition of its category
that libasterix carries: the content test that tells a real data block from octets that
only look like one (a category and a length) in a damaged raw stream
(:func:`mhtrack.io.asterix.resync.judged`).

Rule (EUROCONTROL ASTERIX Part 1, §4): a block's records follow one another, each an
FSPEC then the items it announces, with lengths the category's UAP gives, and the last
ends at the block's end. A category with several UAPs (CAT001 plots and tracks, CAT007)
is read record by record, each by the first of its UAPs that parses it.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import mhtrack.io.asterix._lib as _lib


@cache
def _editions(cat: int) -> tuple[Any, ...]:
    """The UAPs of every edition of ``cat`` (newest last, as libasterix lists them)."""
    gen = _lib.modules()[1]
    return tuple(ed.cv_uap for ed in gen.manifest["CATS"].get(cat, ()))


def fills_any_edition(cat: int, raw: bytes) -> bool:
    """``raw`` (a block's octets after its header) is whole records of ``cat`` by one of
    its editions; ``False`` for a category libasterix does not carry."""
    base = _lib.modules()[0]
    for uap in reversed(_editions(cat)):
        several = getattr(uap, "cv_uaps", None)
        if several is None:
            if not isinstance(_parsed(uap.parse, base.Bits.from_bytes(raw)), ValueError):
                return True
        elif _by_any(tuple(several.values()), raw, base):
            return True
    return False


def _by_any(uaps: tuple[Any, ...], raw: bytes, base: Any) -> bool:
    bits = base.Bits.from_bytes(raw)
    while len(bits):
        for uap in uaps:
            got = _parsed(uap.parse, base.ParsingMode.StrictParsing, bits)
            if not isinstance(got, ValueError):
                bits = got[1]
                break
        else:
            return False
    return True


def _parsed(parse: Any, *args: Any) -> Any:
    """libasterix's result, or a ``ValueError`` for an exception it raises on octets it
    cannot read (some editions' UAPs raise ``TypeError`` on such input)."""
    try:
        return parse(*args)
    except (TypeError, IndexError, KeyError, AttributeError) as e:
        return ValueError(str(e))
