"""The same data block received twice — on the two LANs of a redundant network, or a
re-sent packet — kept once (docs/file-formats.md, "ASTERIX recordings").

Two data blocks are the same when their octets are equal (category, length and records,
so the same SAC/SIC, times and plots); the second is dropped when it arrives within
``window`` s of capture time of the first, or, for a recording without capture times,
within the last ``span`` data blocks. A radar that sends an identical block again later
(the same plots a rotation later cannot be: its time of day differs) is not affected.

A stream of datagrams (``mhtrack live``, :func:`stream_filter`) takes a copy for a copy
whatever its delay within the last ``span`` blocks: a copy later than the window would be
decoded again and its plots — not dropped as late when within the re-order window, or at
the time of the last plot already released — tracked twice (a second LAN 1 s behind
doubled every plot). The octets hold the block's time of day: only a copy can equal them.
Its window is infinite, so the count alone decides (receive times, when given, play no
part), and its state — the blocks remembered and their ages in blocks received — can be
kept in a live run's checkpoint and restored (:meth:`DuplicateFilter.recent`).

Streaming: one :meth:`DuplicateFilter.keep` call per data block, in file order; memory
is bounded by ``span`` digests (16-octet BLAKE2b of each block) whatever the window.
"""

from __future__ import annotations

import hashlib
import math
from collections import OrderedDict

#: Default window (s): redundant LANs deliver both copies within milliseconds; a radar's
#: next identical block would be a rotation (≥ 1 s) later.
WINDOW_S = 0.5
#: Default number of recent blocks remembered.
SPAN = 4096
#: Octets of a block's digest (BLAKE2b), and of its age in :meth:`DuplicateFilter.recent`.
DIGEST = 16
AGE = 4


class DuplicateFilter:
    """``keep(block, time)`` is ``False`` for a block seen within the window; counts in
    :attr:`dropped`."""

    def __init__(self, window: float = WINDOW_S, span: int = SPAN) -> None:
        if not window >= 0.0 or span < 1:
            raise ValueError(f"duplicate window {window} s and span {span} blocks: the "
                             "window must be ≥ 0 and the span ≥ 1")
        self.window, self.span = float(window), int(span)
        self.seen: OrderedDict[bytes, tuple[float | None, int]] = OrderedDict()
        self.count = 0
        self.dropped = 0

    def keep(self, block: bytes, time: float | None = None) -> bool:
        """Whether this data block (its whole octets, header included) is new: not seen
        within ``window`` s (with capture times) or within the last ``span`` blocks."""
        self.count += 1
        key = hashlib.blake2b(block, digest_size=DIGEST).digest()
        prev = self.seen.get(key)
        if prev is not None:
            timed = time is not None and prev[0] is not None and math.isfinite(self.window)
            if abs(time - prev[0]) <= self.window if timed \
                    else self.count - prev[1] <= self.span:
                self.dropped += 1
                return False
            del self.seen[key]
        self.seen[key] = (time, self.count)
        while len(self.seen) > self.span:
            self.seen.popitem(last=False)
        if time is not None:
            while self.seen:
                first_t = next(iter(self.seen.values()))[0]
                if first_t is None or time - first_t <= self.window:
                    break
                self.seen.popitem(last=False)
        return True


    def recent(self) -> str:
        """The blocks remembered, oldest first, as one hex string — per block its digest
        (32 digits) and its age in blocks received since (8 digits, at most ``span + 1``:
        older is as good as forgotten): with :meth:`restore`, the filter of a later run
        (a live run resumed from a checkpoint) decides on the blocks that follow as this
        one would — a copy late across the restart is a copy. For a stream filter (the
        count rule: :func:`stream_filter`)."""
        cap = self.span + 1
        return b"".join(k + min(self.count - c, cap).to_bytes(AGE, "big")
                        for k, (_, c) in self.seen.items()).hex()

    def restore(self, recent: str) -> None:
        """Remember the blocks of :meth:`recent` as received before any of this
        filter's own; a :class:`ValueError` naming what is wrong when ``recent`` is not
        such a string (it may come from a hostile file)."""
        if not isinstance(recent, str):
            raise ValueError(f"recent blocks: expected a hex string, got "
                             f"{type(recent).__name__}")
        size = DIGEST + AGE
        if len(recent) % (2 * size) or len(recent) > 2 * size * self.span:
            raise ValueError(f"recent blocks: {len(recent)} hex digits, expected a multiple "
                             f"of {2 * size} and at most {2 * size * self.span}")
        try:
            raw = bytes.fromhex(recent)
        except ValueError:
            raise ValueError("recent blocks: not a hex string") from None
        entries = [(raw[i:i + DIGEST], int.from_bytes(raw[i + DIGEST:i + size], "big"))
                   for i in range(0, len(raw), size)]
        keys = [k for k, _ in entries]
        if len(set(keys)) != len(keys):
            raise ValueError("recent blocks: a digest appears twice")
        ages = [a for _, a in entries]
        if any(a > self.span + 1 for a in ages) or ages != sorted(ages, reverse=True):
            raise ValueError(f"recent blocks: ages must fall from oldest to newest and be "
                             f"at most {self.span + 1}")
        old = list(self.seen.items())
        # received ``age`` blocks before this filter's count 0
        self.seen = OrderedDict((k, (None, self.count - a)) for k, a in entries)
        for k, v in old:
            self.seen.pop(k, None)
            self.seen[k] = v
        while len(self.seen) > self.span:
            self.seen.popitem(last=False)


def stream_filter(span: int = SPAN) -> DuplicateFilter:
    """The filter of a stream: every block equal to one of the last ``span`` is a copy,
    however late (module docstring)."""
    return DuplicateFilter(window=math.inf, span=span)
