"""A damaged feed for tests and benchmarks: a replay's datagrams sent to several
destinations (the redundant LANs of a surveillance network), each copy dropped or delayed
at random, reproducibly (``mhtrack replay --drop P --delay P:SECONDS --seed N``,
``docs/live.md``).

Rule: for every datagram of the schedule, in order, and every destination, one uniform
draw ``u`` of NumPy's ``default_rng(seed)`` (PCG64): ``u < drop`` — the copy is not sent;
``drop ≤ u < drop + delay`` — it is sent ``delay_s`` seconds of recording time late
(after the copies due before it, before those due after); else it is sent on time. The
draws of the two LANs are independent, as two networks' losses are. The send order is a
function of the recording and ``(drop, delay, delay_s, seed)`` alone, so the same
arguments damage the same copies at every ``--speed`` (``max`` included); the delay, as
the recording's spacing, is divided by the speed.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Damage:
    """Each copy's chance of being dropped, of being delayed, the delay (s of recording
    time) and the random seed."""

    drop: float = 0.0
    delay: float = 0.0
    delay_s: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        if not (0.0 <= self.drop <= 1.0 and 0.0 <= self.delay <= 1.0
                and self.drop + self.delay <= 1.0):
            raise ValueError(f"drop {self.drop!r} and delay {self.delay!r} must be "
                             "chances in [0, 1] with a sum of at most 1")
        if not 0.0 <= self.delay_s < float("inf"):
            raise ValueError(f"the delay must be a finite number of seconds ≥ 0, got "
                             f"{self.delay_s!r}")


@dataclass
class DamageCounts:
    """Copies decided so far: sent on time, delayed (and sent), dropped."""

    on_time: int = 0
    delayed: int = 0
    dropped: int = 0
    per_destination: list[list[int]] = field(default_factory=list)


def damaged(items: Iterable[tuple[int, float]], destinations: int, damage: Damage,
            counts: DamageCounts | None = None) -> Iterator[tuple[int, int, float]]:
    """``(datagram index, destination, due time)`` of every copy sent, in send order,
    from ``(datagram index, due time)`` in due order (:func:`~mhtrack.sources.replay.
    schedule`; due times in s of recording time): the module docstring's rule (a delayed
    copy goes before the copies due at the same time as it). ``counts`` is updated as
    copies are decided (``per_destination[d]`` = ``[sent, dropped]``)."""
    if destinations < 1:
        raise ValueError(f"at least one destination, got {destinations!r}")
    counts = DamageCounts() if counts is None else counts
    counts.per_destination = [[0, 0] for _ in range(destinations)]
    rng = np.random.default_rng(damage.seed)
    late: list[tuple[float, int, int, int]] = []  # (due, draw number, index, destination)
    n = 0
    for i, due in items:
        while late and late[0][0] <= due:
            d, _, j, k = heapq.heappop(late)
            yield j, k, d
        for k, u in enumerate(rng.random(destinations).tolist()):
            n += 1
            if u < damage.drop:
                counts.dropped += 1
                counts.per_destination[k][1] += 1
                continue
            counts.per_destination[k][0] += 1
            if u < damage.drop + damage.delay:
                counts.delayed += 1
                heapq.heappush(late, (due + damage.delay_s, n, i, k))
            else:
                counts.on_time += 1
                yield i, k, due
    while late:
        d, _, j, k = heapq.heappop(late)
        yield j, k, d
