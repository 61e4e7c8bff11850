"""A recording played back as a network feed: ``mhtrack replay REC --to udp://HOST:PORT``
(``docs/live.md``).

Each datagram of a pcap or pcapng recording is sent as it was captured (its ASTERIX
payload, one UDP datagram), at its capture time (the recorder formats: each record at its
own time); a raw recording (data blocks back to back) is sent one data block per
datagram — the blocks ``convert`` reads (:meth:`~mhtrack.io.asterix.decode.Decoder.units`:
in a damaged stream, judged by their content) — at the time of day of the block's first
CAT048/CAT034 record (on one axis across midnight, :class:`TimeAxis`; a block without
one keeps the previous time, blocks before the first timed one take its time). The
spacing of the times is kept, divided by ``speed`` (``math.inf``: as fast as the socket
takes them). ``loops`` plays the file that many times
(``None``: until ``stop``), pass ``n`` ``n · S`` seconds after the first, ``S`` the
recording's span (latest time less earliest) plus one mean spacing rounded up to a whole
second; the times of day
inside the datagrams move on by the same ``n · S`` (:mod:`~mhtrack.io.asterix.retime`:
wrapping at midnight), so that a looped replay is one longer feed, its passes in time
order, not the same minutes again (which ``live`` would drop as late); a recording
without any time of day cannot be moved on (:class:`~mhtrack.errors.InputError`). The
time items' places in each datagram are found once, before the first datagram is sent
(by libasterix, about 3 ms a datagram), then patched at each pass; blocks left unmoved
(:func:`~mhtrack.io.asterix.retime.time_layout`) are counted. Several
destinations (redundant LANs) get every datagram each; ``damage`` drops and delays copies
at random, reproducibly (:mod:`~mhtrack.sources.damage`).
"""

from __future__ import annotations

import math
import mmap
import socket
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from mhtrack.errors import InputError
from mhtrack.io.asterix.decode import Decoder
from mhtrack.io.asterix.framings import recognise
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.retime import patch_times, time_layout
from mhtrack.io.asterix.timeaxis import TimeAxis
from mhtrack.io.paths import check_input_file
from mhtrack.sources.damage import Damage, DamageCounts, damaged
from mhtrack.sources.udp import Endpoint, parse_endpoint


def recording_datagrams(path: str | Path) -> list[tuple[bytes, float]]:
    """``(payload, time)`` of every datagram of the recording ``path`` (module
    docstring), in file order; times in seconds (capture: POSIX; raw: the time axis;
    a recording without any time: all ``0.0``, :func:`has_times` ``False``)."""
    return _datagrams(path)[0]


def has_times(path: str | Path) -> bool:
    """Whether any datagram of the recording ``path`` has a time."""
    return _datagrams(path)[1]


def _datagrams(path: str | Path) -> tuple[list[tuple[bytes, float]], bool]:
    path = check_input_file(Path(path))
    name = str(path)
    decoder, problems = Decoder(), Problems()
    with path.open("rb") as fh:
        size = path.stat().st_size
        with (mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) if size else
              _Empty()) as data:
            kind = recognise(data, name, decoder.categories)
            raw = [(bytes(payload), when) for _, when, payload in decoder.units(
                data, kind, name, problems)]  # raw: one block each, judged as convert does
    whens: list[float | None] = []
    axis = TimeAxis()
    for payload, when in raw:
        if when is None:
            for _, _, found in decoder.blocks(payload, 0, Problems()):
                if found:
                    when = axis.times_list([found[0][0]])[0]
                    break
        whens.append(None if when is None else float(when))
    first = next((w for w in whens if w is not None), None)
    out, last = [], 0.0 if first is None else first
    for (payload, _), when in zip(raw, whens, strict=True):
        last = last if when is None else when
        out.append((payload, last))
    return out, first is not None


class _Empty:
    def __enter__(self) -> bytes:
        return b""

    def __exit__(self, *exc: object) -> None:
        return None


@dataclass
class ReplayStats:
    """What a replay sent."""

    datagrams: int = 0
    bytes: int = 0
    passes: int = 0
    #: Copies dropped and delayed by the ``damage`` (:mod:`~mhtrack.sources.damage`).
    dropped: int = 0
    delayed: int = 0
    #: Blocks sent with their old times in a moved pass (no time items found in them).
    unmoved: int = 0


def _span(times: list[float]) -> float:
    """The latest time less the earliest (a recording need not be in time order)."""
    return max(times) - min(times)


def pass_seconds(times: list[float]) -> int:
    """``S``, the whole seconds from one pass's start to the next (module docstring): the
    span of ``times`` plus their mean spacing, rounded up (at least 1)."""
    if len(times) < 2:
        return 1
    span = _span(times)
    return max(1, math.ceil(span + span / (len(times) - 1)))


def schedule(times: list[float], speed: float, loops: int | None,
             every: float | None = None) -> Iterator[tuple[int, float]]:
    """``(datagram index, due time in s from the start)`` of a replay: the recording's
    spacing divided by ``speed`` (``math.inf``: all due at 0), ``loops`` passes (``None``:
    endless), pass ``n`` starting ``n · every`` after the first (``None``: one mean
    spacing after the last datagram of the one before)."""
    if not times:
        return
    t0, span = times[0], _span(times)
    gap = span / (len(times) - 1) if len(times) > 1 else 0.0
    n = 0
    while loops is None or n < loops:
        base = n * (span + gap if every is None else every)
        for i, t in enumerate(times):
            yield i, (base + max(t - t0, 0.0)) / speed
        n += 1


def replay(path: str | Path, to: str | Endpoint | Sequence[str | Endpoint], *,
           speed: float = 1.0, loops: int | None = 1, stop: threading.Event | None = None,
           clock: Callable[[], float] = time.monotonic,
           sleep: Callable[[float], object] | None = None,
           damage: Damage | None = None, move_times: bool = True) -> ReplayStats:
    """Send the datagrams of recording ``path`` to ``to`` (``udp://HOST:PORT``, or
    several: every datagram to each) on the :func:`schedule` of ``speed`` and ``loops``,
    each copy dropped or delayed by ``damage`` (:func:`~mhtrack.sources.damage.damaged`),
    until done or ``stop`` is set (a wait ends at once when it is: default ``sleep`` is
    ``stop.wait``). ``datagrams`` counts the copies sent. Pass ``n`` moves the times of
    day on by ``n · S`` (module docstring; ``move_times=False``: the same times again)."""
    if sleep is None:
        sleep = time.sleep if stop is None else stop.wait
    if not speed > 0:
        raise ValueError(f"speed must be above 0, got {speed!r}")
    if loops is not None and loops < 1:
        raise ValueError(f"loops must be at least 1, got {loops!r}")
    eps = [to] if isinstance(to, str | Endpoint) else list(to)
    if not eps:
        raise ValueError("replay needs at least one destination")
    eps = [e if isinstance(e, Endpoint) else parse_endpoint(e) for e in eps]
    items, timed = _datagrams(path)
    addrs = [socket.getaddrinfo(e.host, e.port, e.family, socket.SOCK_DGRAM)[0][4][:2]
             for e in eps]
    stats, counts = ReplayStats(), DamageCounts()
    last = len(items) - 1
    times = [t for _, t in items]
    every = pass_seconds(times) if move_times and loops != 1 else None
    if every is not None and items and not timed:
        raise InputError(f"{path}: no datagram has a time of day: its passes cannot be "
                         "moved on (replay it once, or without moving the times)",
                         file=str(path))
    # every datagram's time items found before the clock starts (module docstring)
    layout = [time_layout(p) for p, _ in items] if every is not None else []
    socks = [socket.socket(e.family, socket.SOCK_DGRAM) for e in eps]
    try:
        start = clock()
        plan = damaged(_passes(schedule(times, 1.0, loops, every), last, stats),
                       len(eps), damage or Damage(), counts)
        for j, k, due in plan:
            n, i = divmod(j, len(items))  # pass n, datagram i
            if stop is not None and stop.is_set():
                break
            wait = start + (due / speed if speed < math.inf else 0.0) - clock()
            if wait > 0:
                sleep(wait)
                if stop is not None and stop.is_set():
                    break
            data = items[i][0]
            if every is not None and n:
                fields, unmoved = layout[i]
                data = patch_times(data, fields, n * every, near=items[i][1])
                stats.unmoved += unmoved
            socks[k].sendto(data, addrs[k])
            stats.datagrams += 1
            stats.bytes += len(data)
    finally:
        for s in socks:
            s.close()
    stats.dropped, stats.delayed = counts.dropped, counts.delayed
    return stats


def _passes(items: Iterator[tuple[int, float]], last: int, stats: ReplayStats
            ) -> Iterator[tuple[int, float]]:
    """``items`` with each index numbered on through the passes (``n · (last + 1) + i``
    in pass ``n``), counting in ``stats.passes`` each pass whose last datagram is
    reached."""
    for i, due in items:
        yield stats.passes * (last + 1) + i, due
        stats.passes += i == last
