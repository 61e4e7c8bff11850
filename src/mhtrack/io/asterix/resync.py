"""Reading on after damage in a recording's records (pcap packets, pcapng blocks, recorder
records, raw data blocks; :mod:`mhtrack.io.asterix.framings` gives each framing's test
of a valid record): which records are taken, where reading resumes, what is counted
(docs/file-formats.md, "ASTERIX recordings")."""

from __future__ import annotations

from collections.abc import Callable, Iterator

from mhtrack.io.asterix.problems import Problems

#: Records in a row that confirm where reading resumes after damage.
CONFIRM = 3


def _confirmed(data: bytes, q: int, at: Callable[[int], int]) -> bool:
    """:data:`CONFIRM` valid records in a row from ``q``, or valid ones to the end."""
    for _ in range(CONFIRM):
        if q == len(data):
            return True
        s = at(q)
        if not s:
            return False
        q += s
    return True


def walk(data: bytes, start: int, at: Callable[[int], int], problems: Problems
         ) -> Iterator[tuple[int, int]]:
    """``(offset, length)`` of each valid record from ``start``. A record is taken when the
    records after it confirm it (:data:`CONFIRM` valid ones in a row, or valid ones to the
    end of the file), or else when no record so confirmed starts inside it (it is the last
    good record before damage, not a false length swallowing good records): of two
    readings that both give valid records, the one that goes on through valid records
    wins. After damage, reading resumes at the next confirmed record, searched octet
    by octet (damage may add or remove octets, so no alignment is assumed)."""
    n = len(data)

    def confirmed(q: int) -> bool:
        return _confirmed(data, q, at)

    p = start
    while p < n:
        step = at(p)
        if step and (confirmed(p + step)
                     or not any(confirmed(q) for q in range(p + 1, p + step))):
            yield p, step
            p += step
            continue
        q = p + 1
        while q < n and not confirmed(q):
            q += 1
        problems.add("resync", p)
        problems.add("skipped_octets", p, q - p)
        p = q


def judged(data: bytes, framed: Callable[[int], int], fits: Callable[[bytes], bool]
           ) -> Callable[[int], int]:
    """The length of the raw data block at an offset (0: none) when its framing is valid
    (``framed``) and ``fits`` finds that its records fill it exactly: a damaged
    length that lands on octets framed like a block still leaves records that do not
    end at its end, so the walk resumes at the good blocks it would cover. Remembered
    for the last 64 offsets asked (the walk asks each more than once, a few blocks
    ahead), so that each block is judged once."""
    memo: dict[int, int] = {}

    def at(q: int) -> int:
        if q not in memo:
            if len(memo) >= 64:
                del memo[next(iter(memo))]
            step = framed(q)
            memo[q] = step if step and fits(data[q:q + step]) else 0
        return memo[q]

    return at
