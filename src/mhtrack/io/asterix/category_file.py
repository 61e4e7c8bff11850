"""The rows of one ASTERIX category in a whole recording (any framing of
:mod:`~mhtrack.io.asterix.framings`, recognised by content): what a reference read for
``evaluate --reference`` walks — CAT062 system tracks or CAT021 ADS-B reports. Blocks of
other categories and blocks whose records do not fill them are counted in the
:class:`~mhtrack.io.asterix.problems.Problems`, never passed on. One walk of the file
can serve several categories (:func:`category_blocks`): a reference without CAT062 is
read as CAT021 without reading the file again. The file is walked as ``convert`` walks a
recording (:meth:`~mhtrack.io.asterix.decode.Decoder.units`: a raw stream's blocks
judged by their content), so that a damaged length does not take good blocks with it."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from mhtrack.io.asterix.container import blocks
from mhtrack.io.asterix.decode import Decoder
from mhtrack.io.asterix.framings import recognise
from mhtrack.io.asterix.problems import Problems

#: One block's rows (``raw`` records, the block's file offset, the problems), or
#: ``None`` when its records do not fill it.
BlockRows = Callable[[bytes, int, Problems], "list[tuple[Any, ...]] | None"]
#: A recording walked once: ``(file offset, category, records)`` of every data block,
#: and the problems of its framing.
Walked = tuple[list[tuple[int, int, bytes]], Problems]


def category_blocks(path: str | Path, cats: Sequence[int]) -> Walked:
    """Every data block of recording ``path`` in file order (``cats``: the categories
    wanted, among those libasterix carries: a raw block is judged by them), and the
    framing's problems."""
    decoder = Decoder(duplicates=None)
    if missing := set(cats) - decoder.categories:
        raise ValueError(f"categories {sorted(missing)} are not read (libasterix does not "
                         "carry them)")
    name = str(path)
    data = Path(path).read_bytes()
    kind = recognise(data, name, decoder.categories)
    problems = Problems()
    found = [block for offset, _, payload in decoder.units(data, kind, name, problems)
             for block in blocks(payload, offset, problems)]
    return found, problems


def category_rows(path: str | Path, cat: int, rows_of: BlockRows,
                  walked: Walked | None = None) -> tuple[list[tuple[Any, ...]], Problems]:
    """The rows ``rows_of`` gives for every category-``cat`` block of recording ``path``
    (in file order), and the parts skipped; ``walked``: the file already walked by
    :func:`category_blocks` (else it is walked now)."""
    found, framing = walked if walked is not None else category_blocks(path, (cat,))
    problems = Problems(dict(framing.counts), dict(framing.first), dict(framing.detail))
    rows: list[tuple[Any, ...]] = []
    for at, found_cat, raw in found:
        if found_cat != cat:
            problems.add("unknown_category", at, detail=f"category {found_cat}")
            continue
        got = rows_of(raw, at, problems)
        if got is None:
            problems.add("undecodable", at, detail=f"category {cat}: records do not "
                         "fill the block")
            continue
        rows += got
    return rows, problems
