"""Malformed parts of a recording: counted by kind, the first byte offset kept, and one
warning line per kind at the end (docs/file-formats.md, "ASTERIX recordings")."""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

#: What each kind of problem means, as the warning says it (``{n}`` the count).
KINDS = {
    "non_udp": "{n} packet(s) that carry no ASTERIX (not UDP nor 802.3/LLC: ARP, TCP, IP "
               "fragments, ...) skipped",
    "truncated_block": "{n} truncated data block(s) (length beyond the data) skipped",
    "bad_length": "{n} data block(s) whose length field is below 3 octets: the rest of "
                  "their datagram skipped",
    "undecodable": "{n} data block(s) whose records do not decode to their length skipped",
    "unknown_category": "{n} data block(s) of categories not read here skipped",
    "no_position": "{n} CAT048 report(s) without a measured position (I048/040) skipped",
    "no_time": "{n} CAT048 report(s) without time of day (I048/140) or data source "
               "(I048/010) skipped",
    "trailing": "{n} stray byte(s) after the last data block skipped",
    "resync": "{n} damaged framing record(s) or packet(s): reading went on at the next "
              "valid one",
    "skipped_octets": "{n} octet(s) of damaged framing skipped",
    "bad_time": "{n} packet(s) whose capture time is more than a day from the packets "
                "around it: their capture time not used",
    "duplicate": "{n} data block(s) received twice within the duplicate window (redundant "
                 "LANs, re-sent packets) dropped",
    "impossible": "{n} report(s) with a physically impossible value (latitude beyond "
                  "±90°, time of day beyond a day, ...) refused",
    "no_accuracy": "{n} ADS-B report(s) without a position accuracy (NACp/NUCp 0) and no "
                   "sigma for their station in the sensors file skipped",
    "not_plot": "{n} report(s) that are not plots (no detection, test target, field "
                "monitor, simulated) left out",
    "no_identity": "{n} ADS-B report(s) with neither a target address (I021/080) nor a "
                   "track number (I021/161) skipped",
}


@dataclass
class Problems:
    """Counts of skipped parts by kind, with the first byte offset of each kind."""

    counts: dict[str, int] = field(default_factory=dict)
    first: dict[str, int] = field(default_factory=dict)
    detail: dict[str, str] = field(default_factory=dict)

    def add(self, kind: str, offset: int, n: int = 1, detail: str = "") -> None:
        """Count ``n`` problems of ``kind``, the first at byte ``offset`` of the file."""
        if kind not in KINDS:
            raise ValueError(f"unknown problem kind {kind!r}")
        self.counts[kind] = self.counts.get(kind, 0) + n
        self.first.setdefault(kind, offset)
        if detail and kind not in self.detail:
            self.detail[kind] = detail

    def lines(self, name: str) -> list[str]:
        """One line per kind: ``FILE: 3 truncated ... skipped (first at byte 1234)``."""
        out = []
        for kind in KINDS:
            if kind in self.counts:
                text = KINDS[kind].format(n=self.counts[kind])
                extra = f"; {self.detail[kind]}" if kind in self.detail else ""
                out.append(f"{name}: {text} (first at byte {self.first[kind]}{extra})")
        return out

    def warn(self, name: str) -> None:
        """Log :meth:`lines` as warnings on the ``mhtrack`` logger."""
        log = logging.getLogger("mhtrack")
        for line in self.lines(name):
            log.warning("%s", line)
