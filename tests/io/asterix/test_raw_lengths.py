"""Raw streams whose damaged block length lands on octets framed like a data block
(io/asterix/resync.py ``judged``, fill.py): every other block written is still read,
checked against the blocks written; the former framing-only walk (no content test)
loses the blocks the damaged length covers, so these tests can fail. And a raw file cut
to one block plus part of the next is read (the whole block kept), not refused."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix")

from tests.helpers.plot_blocks import plot_blocks

from mhtrack.io.asterix import read_recording
from mhtrack.io.asterix.decode import Decoder
from mhtrack.io.asterix.framings import _raw_at, units
from mhtrack.io.asterix.problems import Problems

N_BLOCKS, PER_BLOCK = 10, 3


def _blocks() -> list[bytes]:
    """Ten CAT048 blocks of three plots each, from radar SAC 1 / SIC 2."""
    return plot_blocks(N_BLOCKS, PER_BLOCK)


def _with_length(blocks: list[bytes], k: int, length: int) -> tuple[bytes, list[int]]:
    """The stream with block ``k``'s length field set to ``length``; the offsets of the
    other (untouched) blocks."""
    starts = np.cumsum([0] + [len(b) for b in blocks[:-1]]).tolist()
    data = bytearray(b"".join(blocks))
    data[starts[k] + 1:starts[k] + 3] = length.to_bytes(2, "big")
    return bytes(data), [s for i, s in enumerate(starts) if i != k]


def _taken(data: bytes, judged: bool) -> set[int]:
    """Offsets of the blocks the raw reader takes, with or without the content test."""
    decoder = Decoder()
    fits = decoder.fills if judged else None
    return {at for at, _, _ in units(data, "raw", "t.ast", decoder.categories, Problems(),
                                     fits)}


def test_length_covering_the_next_block_exactly() -> None:
    """Block k's length made to cover block k + 1 and end where block k + 2 starts (a
    valid block): all blocks but k are read."""
    blocks = _blocks()
    for k in range(N_BLOCKS - 2):
        data, kept = _with_length(blocks, k, len(blocks[k]) + len(blocks[k + 1]))
        assert set(kept) <= _taken(data, True), k
        assert kept[k] not in _taken(data, False)  # block k + 1, lost by framing alone


def test_length_landing_on_anything_framed_like_a_block() -> None:
    """Every damaged length of blocks 0, 4 and 7 that lands on octets framed like a
    block (a known category, a length that fits): all other blocks are read."""
    blocks = _blocks()
    cats = Decoder().categories
    cases = lost_before = 0
    for k in (0, 4, 7):
        start = sum(len(b) for b in blocks[:k])
        total = sum(len(b) for b in blocks)
        for length in range(3, total - start):
            data, kept = _with_length(blocks, k, length)
            if length == len(blocks[k]) or not _raw_at(data, start + length, cats):
                continue
            cases += 1
            assert set(kept) <= _taken(data, True), (k, length)
            lost_before += not set(kept) <= _taken(data, False)
    assert cases >= 10 and lost_before >= 5, (cases, lost_before)


def test_damaged_length_through_read_recording(tmp_path: Path) -> None:
    """The plots of every untouched block come out of ``read_recording``; the damage is
    counted as one resynchronisation at the damaged block."""
    blocks = _blocks()
    data, _ = _with_length(blocks, 3, len(blocks[3]) + len(blocks[4]) + len(blocks[5]))
    path = tmp_path / "d.ast"
    path.write_bytes(data)
    rec = read_recording(path)
    assert len(rec) == (N_BLOCKS - 1) * PER_BLOCK
    assert rec.problems.counts == {"resync": 1, "skipped_octets": len(blocks[3])}
    assert rec.problems.first["resync"] == sum(len(b) for b in blocks[:3])


def test_one_block_and_a_partial_block_is_read(tmp_path: Path) -> None:
    """A raw file cut to its first block and 5 octets of the second: the first block's
    plots, the 5 octets counted as skipped (not a refusal)."""
    blocks = _blocks()
    path = tmp_path / "cut.ast"
    path.write_bytes(blocks[0] + blocks[1][:5])
    rec = read_recording(path)
    assert len(rec) == PER_BLOCK
    assert rec.problems.counts == {"resync": 1, "skipped_octets": 5}
    assert rec.problems.first["resync"] == len(blocks[0])
