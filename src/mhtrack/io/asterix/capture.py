"""Capture times of pcap and pcapng packets checked against one another: the time axis
takes each plot's day from its packet's capture time (:mod:`~mhtrack.io.asterix.timeaxis`),
so one damaged time must set neither that plot's day nor the whole axis
(docs/file-formats.md, "ASTERIX recordings").

* **Start**: the first packets are checked against the median of the first
  :data:`START` capture times (:func:`start_time`), not against the first one, so a
  damaged time among them, the very first included, is outvoted by the others. pcap's
  reader and pcapng's share this rule.
* **Range**: a time outside ``[0, 2³²)`` s (before 1970 or after 2106, pcap's own 32-bit
  seconds) is damage wherever it comes.
* **Neighbours**: a time more than a day from the last one taken is damage (a flipped
  high bit of a timestamp). pcap's reader refuses such a packet as damaged framing
  (``resync``); pcapng's keeps its plots without the time (:class:`CaptureClock`,
  ``bad_time``), and takes the next time that agrees with the refused one rather than
  with the last one taken (the clock was set).
"""

from __future__ import annotations

from collections.abc import Sequence

from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import DAY_S

#: Capture times at or beyond this (s, 2³²: pcap's 32-bit seconds, the year 2106) are damage.
MAX_CAPTURE_S = 2.0 ** 32
#: The first packets whose median capture time starts the check.
START = 5


def plausible(t: float) -> bool:
    """``t`` (POSIX s) lies in ``[0, 2³²)``: a time some clock can give."""
    return 0.0 <= t < MAX_CAPTURE_S


def start_time(times: Sequence[float]) -> float | None:
    """The median of the first :data:`START` of ``times`` (the upper one of an even
    count; ``None`` for none): the reference the first packets are checked against."""
    first = sorted(times[:START])
    return first[len(first) // 2] if first else None


class CaptureClock:
    """pcapng capture times checked one by one, in file order (module docstring): a time
    is taken when it is :func:`plausible` and within a day of the last one taken (at the
    start, :meth:`start`'s median) or of the last one refused; else it is damage, counted
    as ``bad_time`` and not used (``None``: the time axis then goes by the times of day
    alone)."""

    def __init__(self, problems: Problems) -> None:
        self.problems = problems
        self.last: float | None = None  # the last time taken (at first: the start)
        self.odd: float | None = None  # the last time refused

    def start(self, times: Sequence[float | None]) -> None:
        """Check the first packets against the median of ``times`` (the first packets'
        capture times, ``None`` and implausible ones left out: :func:`start_time`)."""
        self.last = start_time([t for t in times if t is not None and plausible(t)])

    def take(self, t: float | None, offset: int) -> float | None:
        """``t`` if it is plausible, else ``None`` (counted at byte ``offset``)."""
        if t is None:
            return None
        if not plausible(t):
            self.problems.add("bad_time", offset)
            return None
        if self.last is None or abs(t - self.last) <= DAY_S \
                or (self.odd is not None and abs(t - self.odd) <= DAY_S):
            self.last, self.odd = t, None
            return t
        self.odd = t
        self.problems.add("bad_time", offset)
        return None
