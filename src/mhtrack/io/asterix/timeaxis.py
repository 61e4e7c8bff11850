"""A monotonic time axis for ASTERIX times of day (I048/140, I034/030, I062/070: seconds
since midnight UTC, modulo 86 400 s).

The axis is seconds since midnight UTC of the recording's first day: ``t = tod + 86 400 d``
with ``d`` the day of the message counted from that first day. The day ``d`` of a message:

* **with a capture timestamp** ``c`` (POSIX seconds; pcap and pcapng packets have one):
  the day whose ``tod`` is nearest ``c`` — ``D = round((c − tod) / 86 400)`` — counted
  from the first message's ``D``. Midnight rollovers and gaps of any length (hours, days)
  follow the capture clock, which needs only to be right to within 12 h;
* **without one** (raw data blocks, datagrams without times), from the latest time ``m``
  of the axis so far (day ``k``, time of day ``m_tod``): a step back of more than 12 h
  (``tod < m_tod − 43 200``) is the next day (23:59 → 00:01); a step forward of more than
  ``24 h −`` :data:`MAX_LATE_S` is a message of the previous day arriving late (00:00:05
  then 23:59:58); any other step is the same day (a late message, or a gap of up to
  23 h forward). The first message is day 0.
"""

from __future__ import annotations

import math

import numpy as np

#: Seconds in a day: times of day are modulo this.
DAY_S = 86400.0
#: Without capture times, a message may be late across midnight by at most this (s):
#: a step forward of more than ``DAY_S − MAX_LATE_S`` is read as the previous day.
MAX_LATE_S = 3600.0
_HALF = DAY_S / 2


class TimeAxis:
    """Maps times of day, in arrival order, to the monotonic axis (module docstring)."""

    def __init__(self) -> None:
        self.day0: int | float | None = None  # capture day of the axis' first day
        self.latest: float | None = None  # largest time on the axis so far

    def times(self, tod: np.ndarray | list[float], capture: float | None = None
              ) -> np.ndarray:
        """Times on the axis of the times of day ``tod`` (arrival order), all captured at
        ``capture`` (POSIX s) or without a capture time (``None``)."""
        return np.array(self.times_list(np.asarray(tod, float).reshape(-1).tolist(),
                                        capture), float)

    def times_list(self, tod: list[float], capture: float | None = None) -> list[float]:
        """:meth:`times` of a list of floats, as a list (a data block's few records: plain
        Python is faster than NumPy there)."""
        out = []
        latest = self.latest
        if capture is not None:
            c = float(capture)
            for x in tod:
                day = round((c - x) / DAY_S)  # half to even, as numpy.round
                if self.day0 is None:
                    self.day0 = day if latest is None else day - self._day_without(x)
                y = x + DAY_S * (day - self.day0)
                out.append(y)
                if latest is None or y > latest:
                    latest = self.latest = y
        else:
            for x in tod:
                d = 0.0 if latest is None else self._day_without(x)
                y = x + DAY_S * d
                out.append(y)
                if latest is None or y > latest:
                    latest = self.latest = y
        return out

    def _day_without(self, x: float) -> int:
        """Day of time of day ``x`` by the rule without capture times."""
        assert self.latest is not None
        k = math.floor(self.latest / DAY_S)
        step = x - (self.latest - k * DAY_S)
        if step < -_HALF:
            return k + 1
        if step > DAY_S - MAX_LATE_S:
            return k - 1
        return k


def unwrap_days(tod: np.ndarray) -> np.ndarray:
    """Times of day (s, arrival order) without capture times on one monotonic axis
    (:class:`TimeAxis`): 23:59 → 00:01 runs on past 86 400 s; small steps back (jitter
    between radars) stay as they are."""
    return TimeAxis().times(tod)
