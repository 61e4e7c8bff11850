"""The rows of one ASTERIX category in a whole recording (any framing of
:mod:`~mhtrack.io.asterix.framings`, recognised by content): what a reference read for
``evaluate --reference`` walks — CAT062 system tracks or CAT021 ADS-B reports. Blocks of
other categories and blocks whose records do not fill them are counted in the
:class:`~mhtrack.io.asterix.problems.Problems`, never passed on."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix.container import blocks
from mhtrack.io.asterix.framings import recognise, units
from mhtrack.io.asterix.problems import Problems

#: One block's rows (``raw`` records, the block's file offset, the problems), or
#: ``None`` when its records do not fill it.
BlockRows = Callable[[bytes, int, Problems], "list[tuple[Any, ...]] | None"]


def category_rows(path: str | Path, cat: int, rows_of: BlockRows
                  ) -> tuple[list[tuple[Any, ...]], Problems]:
    """The rows ``rows_of`` gives for every category-``cat`` block of recording ``path``
    (in file order), and the parts skipped."""
    gen = _lib.modules()[1]
    name = str(path)
    data = Path(path).read_bytes()
    cats = {int(c) for c in gen.manifest["CATS"]} | {cat}
    kind = recognise(data, name, cats)
    problems = Problems()
    rows: list[tuple[Any, ...]] = []
    for offset, _, payload in units(data, kind, name, cats, problems):
        for at, found_cat, raw in blocks(payload, offset, problems):
            if found_cat != cat:
                problems.add("unknown_category", at, detail=f"category {found_cat}")
                continue
            found = rows_of(raw, at, problems)
            if found is None:
                problems.add("undecodable", at, detail=f"category {cat}: records do not "
                             "fill the block")
                continue
            rows += found
    return rows, problems
