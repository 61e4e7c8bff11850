"""CAT062 data blocks of track rows, encoded with NumPy: the octets libasterix writes
for the messages of :func:`~mhtrack.io.asterix.cat062.track_messages`
(``encode_blocks``), without building a Python object per item — a live run sends every
frame's rows, and libasterix's per-record objects cost more CPU than the tracking (and
``export --category 062`` of a tracks file ~15× the time). :func:`row_blocks` is the
one path of every CAT062 writer: the sinks (:func:`blocks062`) and the export.

A record (EUROCONTROL ASTERIX CAT062 edition 1.18, user application profile) holds, in
FRN order, I062/010 (SAC, SIC), 070 (time of day, 1/128 s, 3 octets), 105 (latitude,
longitude: two's complement, 4 octets each, 180/2²⁵°), 185 (VX, VY: 2 octets each, ¼
m/s), 040 (track number, 2 octets) and 080 (track status, four octets: CNF the second
lowest bit of the first, CST the highest of the fourth; FX set on the first three). Its
FSPEC is two octets: FRN 1, 4, 5, 7 and FX, then FRN 12 and 13. Values big-endian.
Data blocks: category 62, their length (2 octets), at most
:data:`~mhtrack.io.asterix.encode.MAX_RECORDS` records, rows in time order (stable) —
``encode_blocks``' rule for one data source. Rows with attributes (I062/060, 136, 220,
245, 290, 340, 380, 500) are encoded by :mod:`.cat062_attr_octets`, and by libasterix
where that module does not cover them (codes beyond 12 bits, …: its docstring).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from mhtrack.io.asterix.encode import MAX_RECORDS

if TYPE_CHECKING:
    from mhtrack.attributes import TrackAttributes
    from mhtrack.models.geodesy import LocalFrame
    from mhtrack.progress import Count
    from mhtrack.records import TrackTable

#: The FSPEC of a record with items 010, 070, 105, 185 | 040, 080.
FSPEC = (0x9B, 0x0C)
#: Octets of one record: FSPEC 2, 010 2, 070 3, 105 8, 185 4, 040 2, 080 4.
RECORD = 25


def records062(raw: dict[str, np.ndarray | int], tentative: np.ndarray,
               coasting: np.ndarray) -> np.ndarray:
    """The records of the rows (``raw``: :func:`~mhtrack.io.asterix.cat062.core_raw`)
    as an ``(n, RECORD)`` array of octets (module docstring)."""
    n = len(raw["tod"])  # type: ignore[arg-type]
    out = np.zeros((n, RECORD), np.uint8)
    out[:, 0], out[:, 1] = FSPEC
    out[:, 2], out[:, 3] = int(raw["sac"]), int(raw["sic"])  # type: ignore[call-overload]
    at = 4
    for key, size in (("tod", 3), ("lat", 4), ("lon", 4), ("vx", 2), ("vy", 2),
                      ("track", 2)):
        v = np.asarray(raw[key], np.int64) & ((1 << (8 * size)) - 1)  # two's complement
        for k in range(size):
            out[:, at + k] = (v >> (8 * (size - 1 - k))) & 0xFF
        at += size
    out[:, at] = 0x01 | (np.asarray(tentative) != 0).astype(np.uint8) << 1
    out[:, at + 1] = out[:, at + 2] = 0x01
    out[:, at + 3] = (np.asarray(coasting) != 0).astype(np.uint8) << 7
    return out


def blocks062(tracks: TrackTable, frame: LocalFrame, name: str, *,
              sac: int | None = None, sic: int | None = None
              ) -> Iterator[tuple[float, int, bytes]]:
    """``(time, data source, CAT062 data block)`` of tracker rows ``tracks``: the
    blocks of :func:`~mhtrack.sinks.files.cat062_blocks`, octet for octet — those of
    :func:`row_blocks` of the rows' :func:`~mhtrack.io.asterix.cat062.table_values`."""
    from mhtrack.io.asterix.cat062 import table_values

    return row_blocks(table_values(tracks, frame, name), tracks.attrs, sac=sac, sic=sic)


def row_blocks(values: tuple[Any, ...], attrs: TrackAttributes | None, *,
               sac: int | None = None, sic: int | None = None, bar: Count | None = None
               ) -> Iterator[tuple[float, int, bytes]]:
    """``(time, data source, CAT062 data block)`` of rows ``values`` (the arguments of
    :func:`~mhtrack.io.asterix.cat062.track_messages` up to ``check``) with attributes
    ``attrs``: the one place that decides how rows become CAT062 (the sinks'
    :func:`blocks062`, ``export --category 062``). The octets libasterix writes of
    ``encode_blocks(track_messages(...))``, encoded with NumPy: rows without attributes
    here (module docstring), rows with attributes by :mod:`.cat062_attr_octets`; by
    libasterix when that module does not cover the attributes (its ``covered``). Values
    that do not fit are refused as ``track_messages`` refuses them (the same checks).
    ``bar`` counts the rows encoded."""
    from mhtrack.io.asterix.cat062 import core_raw, track_messages
    from mhtrack.io.asterix.cat062_attr_octets import covered, record_segments
    from mhtrack.io.asterix.cat062_items import attribute_raw
    from mhtrack.io.asterix.encode import encode_blocks
    from mhtrack.io.asterix.octets import assemble

    time, coasting, tentative, check = values[0], values[6], values[7], values[8]
    raw = core_raw(*values, sac=sac, sic=sic)
    order = np.argsort(time, kind="stable")
    sid = int(raw["sid"])
    if attrs is None:
        recs = records062(raw, tentative, coasting)[order]
        data, sizes = recs.reshape(-1), np.full(len(order), RECORD)
    else:
        v = attribute_raw(attrs, check)
        if not covered(attrs, v):
            yield from encode_blocks(track_messages(*values, sac=sac, sic=sic,
                                                    attrs=attrs), bar)
            return
        data, sizes = assemble(record_segments(raw, tentative, coasting, attrs, v), order)
    ends = np.concatenate([[0], np.cumsum(sizes)])
    for i in range(0, len(order), MAX_RECORDS):
        j = min(i + MAX_RECORDS, len(order))
        size = 3 + int(ends[j] - ends[i])
        if bar is not None:
            bar.update(j - i)
        yield (float(time[order[i]]), sid,
               bytes((62, size >> 8, size & 0xFF)) + data[ends[i]:ends[j]].tobytes())
