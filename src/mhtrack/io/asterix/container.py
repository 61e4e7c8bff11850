"""The data blocks of ASTERIX octets: each block framed by its header of category and
2-octet length (EUROCONTROL ASTERIX Part 1, §4). The octets come from a recording's
units (:func:`mhtrack.io.asterix.framings.units`: pcap, pcapng, recorder formats or raw
streams, recognised by content) or from datagrams; each block comes with its byte offset
in the file, so that every problem found later can name where it is.
"""

from __future__ import annotations

from collections.abc import Iterator

from mhtrack.io.asterix.problems import Problems


def blocks(payload: bytes, base: int, problems: Problems
           ) -> Iterator[tuple[int, int, bytes]]:
    """``(file offset, category, records)`` of each data block of a payload (its header
    of category and 2-octet length framing it). A length below 3 skips the rest of the
    payload, a length beyond it the block (both counted)."""
    pos, n = 0, len(payload)
    while pos < n:
        if n - pos < 3:
            problems.add("trailing", base + pos, n - pos)
            return
        cat = payload[pos]
        length = (payload[pos + 1] << 8) | payload[pos + 2]
        if length < 3:
            problems.add("bad_length", base + pos)
            return
        if pos + length > n:
            problems.add("truncated_block", base + pos)
            return
        yield base + pos, cat, payload[pos + 3:pos + length]
        pos += length
