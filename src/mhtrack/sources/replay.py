"""A recording played back as a network feed: ``mhtrack replay REC --to udp://HOST:PORT``
(``docs/live.md``).

Each datagram of a pcap or pcapng recording is sent as it was captured (its ASTERIX
payload, one UDP datagram), at its capture time (the recorder formats: each record at its
own time); a raw recording (data blocks back to back) is sent one data block per
datagram, at the time of day of the block's first CAT048/CAT034 record (on one axis
across midnight, :class:`TimeAxis`; a block without one keeps the previous time). The
spacing of the times is kept, divided by ``speed`` (``math.inf``: as fast as the socket
takes them). ``loops`` plays the file that many times
(``None``: until ``stop``), pass ``n`` ``n · S`` seconds after the first, ``S`` the
recording's span plus one mean spacing rounded up to a whole second; the times of day
inside the datagrams move on by the same ``n · S`` (:mod:`~mhtrack.io.asterix.retime`:
wrapping at midnight), so that a looped replay is one longer feed, its passes in time
order, not the same minutes again (which ``live`` would drop as late). The time items'
places in each datagram are found once (by libasterix, about 3 ms a datagram), then
patched at each pass. Several
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

from mhtrack.io.asterix.decode import Decoder
from mhtrack.io.asterix.framings import recognise, units
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.retime import patch_times, time_fields
from mhtrack.io.asterix.timeaxis import TimeAxis
from mhtrack.io.paths import check_input_file
from mhtrack.sources.damage import Damage, DamageCounts, damaged
from mhtrack.sources.udp import Endpoint, parse_endpoint


def recording_datagrams(path: str | Path) -> list[tuple[bytes, float]]:
    """``(payload, time)`` of every datagram of the recording ``path`` (module
    docstring), in file order; times in seconds (capture: POSIX; raw: the time axis)."""
    path = check_input_file(Path(path))
    name = str(path)
    decoder, problems = Decoder(), Problems()
    with path.open("rb") as fh:
        size = path.stat().st_size
        with (mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) if size else
              _Empty()) as data:
            kind = recognise(data, name, decoder.categories)
            raw = [(bytes(payload), when) for _, when, payload in units(
                data, kind, name, decoder.categories, problems)]  # raw: one block each
    out, axis, last = [], TimeAxis(), 0.0
    for payload, when in raw:
        if when is None:
            for _, _, found in decoder.blocks(payload, 0, Problems()):
                if found:
                    when = axis.times_list([found[0][0]])[0]
                    break
        last = last if when is None else float(when)
        out.append((payload, last))
    return out


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


def pass_seconds(times: list[float]) -> int:
    """``S``, the whole seconds from one pass's start to the next (module docstring): the
    span of ``times`` plus their mean spacing, rounded up (at least 1)."""
    if len(times) < 2:
        return 1
    span = times[-1] - times[0]
    return max(1, math.ceil(span + span / (len(times) - 1)))


def schedule(times: list[float], speed: float, loops: int | None,
             every: float | None = None) -> Iterator[tuple[int, float]]:
    """``(datagram index, due time in s from the start)`` of a replay: the recording's
    spacing divided by ``speed`` (``math.inf``: all due at 0), ``loops`` passes (``None``:
    endless), pass ``n`` starting ``n · every`` after the first (``None``: one mean
    spacing after the last datagram of the one before)."""
    if not times:
        return
    t0, span = times[0], times[-1] - times[0]
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
    items = recording_datagrams(path)
    addrs = [socket.getaddrinfo(e.host, e.port, e.family, socket.SOCK_DGRAM)[0][4][:2]
             for e in eps]
    stats, counts = ReplayStats(), DamageCounts()
    socks = [socket.socket(e.family, socket.SOCK_DGRAM) for e in eps]
    last = len(items) - 1
    times = [t for _, t in items]
    every = pass_seconds(times) if move_times else None
    fields: dict[int, tuple[tuple[int, int, int], ...]] = {}
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
                if i not in fields:
                    fields[i] = time_fields(data)
                data = patch_times(data, fields[i], n * every, near=items[i][1])
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
