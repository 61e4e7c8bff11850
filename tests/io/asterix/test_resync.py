"""The walk over a recording's records after damage (io/asterix/resync.py), on a framing
given as a table of the offsets where a valid record starts and its length: which
reading wins when two both give valid records, worked by hand."""

from __future__ import annotations

from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.resync import walk


def _walk(n: int, valid: dict[int, int]) -> tuple[list[tuple[int, int]], Problems]:
    problems = Problems()
    return list(walk(bytes(n), 0, lambda q: valid.get(q, 0), problems)), problems


def test_of_two_valid_readings_the_one_going_on_through_valid_records_wins() -> None:
    """Real records at 0, 8, 13, 18 (ending at 23); the record at 0 damaged: its length
    reads 10, past the start of the record at 8, and its last two octets with the next
    two read as a valid record of 4 (at 10), after which nothing is valid (14). Reading
    on from 10 gives one valid record, from 8 three to the end: the record at 8 is kept,
    the damaged one skipped. (Taking a record whenever the next one is valid kept the
    damaged record and the false one and lost the record at 8.)"""
    got, problems = _walk(23, {0: 10, 10: 4, 8: 5, 13: 5, 18: 5})
    assert got == [(8, 5), (13, 5), (18, 5)]
    assert problems.counts == {"resync": 1, "skipped_octets": 8}
    assert problems.first == {"resync": 0, "skipped_octets": 0}


def test_a_damaged_record_with_nothing_confirmed_inside_is_taken() -> None:
    """The last good records before damage: the record after the one at 0 (at 10) is
    valid but not confirmed, and no confirmed record starts inside either, so both are
    kept; the two octets after them are skipped and reading resumes at 16."""
    got, problems = _walk(26, {0: 10, 10: 4, 16: 5, 21: 5})
    assert got == [(0, 10), (10, 4), (16, 5), (21, 5)]
    assert problems.counts == {"resync": 1, "skipped_octets": 2}
    assert problems.first["resync"] == 14


def test_undamaged_records_are_all_taken() -> None:
    """Records back to back to the end, two of them only (fewer than CONFIRM)."""
    assert _walk(9, {0: 4, 4: 5})[0] == [(0, 4), (4, 5)]
    assert _walk(20, {0: 5, 5: 5, 10: 5, 15: 5})[0] == [(0, 5), (5, 5), (10, 5), (15, 5)]
