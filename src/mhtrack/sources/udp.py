"""Datagrams from the network or stdin, with their receive times (``docs/live.md``).

:class:`UdpReader` listens on one or more UDP endpoints (``udp://HOST:PORT``; a
multicast group as HOST joins that group on every interface; IPv6 as
``udp://[::1]:PORT``); several endpoints (redundant LANs) are merged in arrival order:
the sockets are read in turn, one datagram from each a round, until a round finds none —
not one socket emptied before the next, which at ``replay --speed max`` put one LAN's
copies thousands of datagrams (seconds of data) behind the other's and dropped its plots
that only it carried as late.
:class:`StdinReader` reads a byte stream: ``raw`` — ASTERIX data blocks back to back (a
``.ast`` file; each block one datagram, framed by its category octet and 2-octet length),
or ``len32`` — each datagram preceded by its length as a 4-octet big-endian integer.

Both are iterables of ``(datagram, receive time)`` (POSIX seconds, ``time.time()`` when
the bytes were read) for :class:`~mhtrack.sources.datagrams.DatagramSource`. A thread
drains the sockets into a queue as soon as datagrams arrive, so a slow tracker step does
not overflow the kernel's socket buffer; the queue is bounded (``max_queued``), and a
datagram that does not fit is dropped and counted (``stats.queue_dropped``), never
silently. The kernel's own drops — datagrams that found a socket's receive buffer full
— are read from the socket on Linux (``SO_RXQ_OVFL``: each datagram carries the
socket's running count of drops before it, as ancillary data of ``recvmsg``) and summed
over the sockets in ``stats.kernel_dropped``; ``None`` where the option is not available
(other systems; stdin, a pipe, never drops). Drops after the last datagram read show with
the next one. Setting the ``stop`` event (:func:`stop_on_signals`: SIGTERM, Ctrl-C) ends the
iteration cleanly: the sockets are drained once more without waiting, every datagram
already received is yielded, then the iteration ends — the source then finishes the
frames it holds.

With ``idle_s`` the iteration also yields :data:`~mhtrack.sources.base.IDLE` (once)
when no datagram has come for ``idle_s`` seconds of ``clock`` (injectable: tests pass
their own): the feed has gone quiet, and the source closes the frames it holds instead
of waiting for plots that may never come (``docs/live.md``, *A silent feed*). Only a
live run asks for it: a recording read from a file has no wall clock, and gives the
same frames every time.
"""

from __future__ import annotations

import contextlib
import ipaddress
import os
import queue
import selectors
import signal
import socket
import struct
import sys
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any, BinaryIO
from urllib.parse import urlsplit

from mhtrack.sources.base import IDLE

#: Receive buffer asked of the kernel per socket (bytes; Linux caps it at
#: ``net.core.rmem_max`` unless run as root).
DEFAULT_RCVBUF = 8 << 20
#: Datagrams held between the receiving thread and the tracker at most.
DEFAULT_MAX_QUEUED = 1_000_000
#: How often (s) a blocked reader looks at its stop event.
POLL_S = 0.05
#: Largest UDP payload.
MAX_DATAGRAM = 65535
STDIN_FRAMINGS = ("raw", "len32")
#: Linux's ``SO_RXQ_OVFL`` (``asm-generic/socket.h``; not in Python's socket module):
#: a socket option asking for the drop count as ancillary data of each datagram.
SO_RXQ_OVFL = 40
#: The drop count is an unsigned 32-bit counter (it wraps).
_U32 = 1 << 32


@dataclass(frozen=True)
class Endpoint:
    """A UDP address to listen on or send to: ``host`` (an IPv4 or IPv6 literal or a
    name), ``port``; ``multicast`` when ``host`` is a multicast group."""

    host: str
    port: int

    @property
    def multicast(self) -> bool:
        with contextlib.suppress(ValueError):
            return ipaddress.ip_address(self.host).is_multicast
        return False

    @property
    def family(self) -> int:
        with contextlib.suppress(ValueError):
            if ipaddress.ip_address(self.host).version == 6:
                return socket.AF_INET6
        return socket.AF_INET

    def __str__(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"udp://{host}:{self.port}"


def parse_endpoint(url: str) -> Endpoint:
    """``udp://HOST:PORT`` (IPv6 in brackets) as an :class:`Endpoint`; a
    :class:`ValueError` naming ``url`` otherwise."""
    parts = urlsplit(url)
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme != "udp" or not parts.hostname or port is None or parts.path:
        raise ValueError(f"{url}: expected udp://HOST:PORT (IPv6: udp://[ADDR]:PORT)")
    return Endpoint(parts.hostname, port)


def listen_socket(ep: Endpoint, rcvbuf: int = DEFAULT_RCVBUF) -> socket.socket:
    """A bound, non-blocking UDP socket for ``ep``: unicast binds ``host:port``; a
    multicast group binds the port on every address and joins the group (default
    interface)."""
    sock = socket.socket(ep.family, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        if ep.multicast:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            group = socket.inet_pton(ep.family, ep.host)
            if ep.family == socket.AF_INET6:
                sock.bind(("::", ep.port))
                sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_JOIN_GROUP,
                                group + (0).to_bytes(4, "little"))
            else:
                sock.bind(("", ep.port))
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                                group + socket.inet_aton("0.0.0.0"))
        else:
            sock.bind((ep.host, ep.port))
        sock.setblocking(False)
    except OSError as e:
        sock.close()
        raise OSError(f"{ep}: cannot listen: {e.strerror or e}") from None
    return sock


@dataclass
class ReaderStats:
    """What a reader received so far."""

    datagrams: int = 0
    bytes: int = 0
    #: Datagrams dropped because the queue to the tracker was full.
    queue_dropped: int = 0
    #: Datagrams received per endpoint (``str(endpoint)``, or ``"stdin"``).
    per_input: dict[str, int] = field(default_factory=dict)
    #: Datagrams the kernel dropped for a full socket buffer (all sockets; ``None``:
    #: not available, module docstring).
    kernel_dropped: int | None = None


def drop_counting(sock: socket.socket) -> bool:
    """Ask the kernel for ``sock``'s drop count with every datagram (``SO_RXQ_OVFL``,
    Linux); whether it was granted."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        sock.setsockopt(socket.SOL_SOCKET, SO_RXQ_OVFL, 1)
    except OSError:
        return False
    return True


def drop_count(ancdata: list[tuple[int, int, bytes]]) -> int | None:
    """The socket's running drop count carried by one datagram's ancillary data
    (``SO_RXQ_OVFL``: a native unsigned 32-bit integer); ``None`` without one (the
    kernel sends it only once a drop has happened)."""
    for level, kind, data in ancdata:
        if level == socket.SOL_SOCKET and kind == SO_RXQ_OVFL and len(data) >= 4:
            return int(struct.unpack("=I", data[:4])[0])
    return None


class _Threaded(ABC):
    """A receiving thread filling a bounded queue; iteration yields from the queue until
    the thread has ended (stop set, or end of input) and the queue is empty."""

    def __init__(self, stop: threading.Event | None, max_queued: int,
                 idle_s: float | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if idle_s is not None and not idle_s > 0:
            raise ValueError(f"idle_s must be > 0 s, got {idle_s!r}")
        self.stop = threading.Event() if stop is None else stop
        #: Yield :data:`IDLE` after this long without a datagram (``None``: never).
        self.idle_s, self.clock = idle_s, clock
        #: Times :data:`IDLE` was yielded.
        self.idles = 0
        self.stats = ReaderStats()
        self._queue: queue.Queue[tuple[bytes, float]] = queue.Queue(max_queued)
        self._thread: threading.Thread | None = None
        self.error: BaseException | None = None

    def _put(self, data: bytes, when: float, where: str) -> None:
        s = self.stats
        try:
            self._queue.put_nowait((data, when))
        except queue.Full:
            s.queue_dropped += 1
            return
        s.datagrams += 1
        s.bytes += len(data)
        s.per_input[where] = s.per_input.get(where, 0) + 1

    def waiting(self) -> int:
        """Datagrams received and not yet taken (approximately: the receiving thread
        goes on)."""
        return self._queue.qsize()

    @abstractmethod
    def _receive(self) -> None:
        """Put what the input delivers on the queue (:meth:`_put`) until stop or its end."""

    def _run(self) -> None:
        try:
            self._receive()
        except BaseException as e:
            self.error = e

    def start(self) -> None:
        """Start receiving (iteration starts it too)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="mhtrack-receive",
                                            daemon=True)
            self._thread.start()

    def __iter__(self) -> Iterator[Any]:
        """``(datagram, receive time)`` as they come; :data:`IDLE` once after each quiet
        spell of ``idle_s`` (module docstring)."""
        self.start()
        assert self._thread is not None
        last, told = self.clock(), False
        while True:
            try:
                item = self._queue.get(timeout=POLL_S)
            except queue.Empty:
                pass
            else:
                last, told = self.clock(), False
                yield item
                continue
            if not self._thread.is_alive() and self._queue.empty():
                break
            if self.idle_s is not None and not told and self.clock() - last >= self.idle_s:
                told = True
                self.idles += 1
                yield IDLE
        self._thread.join()
        if self.error is not None:
            raise self.error


class UdpReader(_Threaded):
    """``(datagram, receive time)`` from the UDP ``endpoints`` (``udp://…`` strings or
    :class:`Endpoint`), merged in arrival order, until ``stop`` is set (module
    docstring). The sockets are bound when the reader is made (:attr:`addresses`: the
    bound ``host, port`` of each, so port 0 picks a free port)."""

    def __init__(self, endpoints: list[str | Endpoint], *, stop: threading.Event | None = None,
                 rcvbuf: int = DEFAULT_RCVBUF, max_queued: int = DEFAULT_MAX_QUEUED,
                 idle_s: float | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__(stop, max_queued, idle_s, clock)
        if not endpoints:
            raise ValueError("no endpoint to listen on")
        self.endpoints = [e if isinstance(e, Endpoint) else parse_endpoint(e)
                          for e in endpoints]
        self.sockets: list[socket.socket] = []
        try:
            for ep in self.endpoints:
                self.sockets.append(listen_socket(ep, rcvbuf))
        except OSError:
            self.close()
            raise
        self.addresses = [s.getsockname()[:2] for s in self.sockets]
        #: Each socket's drop count as last seen (``None``: not counted, module
        #: docstring); the total in ``stats.kernel_dropped``.
        self._drops: list[int] | None = [0] * len(self.sockets) if all(
            drop_counting(s) for s in self.sockets) else None
        self.stats.kernel_dropped = None if self._drops is None else 0
        self.names = [str(Endpoint(ep.host, a[1])) for ep, a in
                      zip(self.endpoints, self.addresses, strict=True)]

    def _drain(self) -> None:
        """Read every socket in turn, one datagram each a round, until a round finds
        none (module docstring)."""
        pairs = list(zip(self.sockets, self.names, strict=True))
        drops, space = self._drops, socket.CMSG_SPACE(4)
        got = True
        while got:
            got = False
            for i, (sock, name) in enumerate(pairs):
                try:
                    if drops is None:
                        data = sock.recv(MAX_DATAGRAM)
                    else:
                        data, anc, _, _ = sock.recvmsg(MAX_DATAGRAM, space)
                        seen = drop_count(anc)
                        if seen is not None and seen != drops[i] % _U32:
                            drops[i] += (seen - drops[i]) % _U32  # a running count
                            self.stats.kernel_dropped = sum(drops)
                except (BlockingIOError, InterruptedError):
                    continue
                self._put(data, time.time(), name)
                got = True

    def _receive(self) -> None:
        with selectors.DefaultSelector() as sel:
            for sock, name in zip(self.sockets, self.names, strict=True):
                sel.register(sock, selectors.EVENT_READ, name)
            while not self.stop.is_set():
                if sel.select(POLL_S):
                    self._drain()
            self._drain()  # what the kernel holds at the stop
        self.close()

    def close(self) -> None:
        """Close the sockets."""
        for s in self.sockets:
            s.close()


class StdinReader(_Threaded):
    """``(datagram, receive time)`` from a binary stream (``framing``: ``raw`` or
    ``len32``, module docstring) until its end or ``stop``. A stream that ends inside a
    datagram raises :class:`ValueError` naming the byte offset."""

    def __init__(self, stream: BinaryIO, *, framing: str = "raw",
                 stop: threading.Event | None = None,
                 max_queued: int = DEFAULT_MAX_QUEUED, name: str = "stdin",
                 idle_s: float | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__(stop, max_queued, idle_s, clock)
        if framing not in STDIN_FRAMINGS:
            raise ValueError(f"unknown stdin framing {framing!r} (expected "
                             f"{', '.join(STDIN_FRAMINGS)})")
        self.stream, self.framing, self.name = stream, framing, name

    def _length(self, buf: bytearray | bytes) -> int | None:
        """Bytes of the next datagram with its framing, once its header is in ``buf``."""
        if self.framing == "raw":
            return int.from_bytes(buf[1:3], "big") if len(buf) >= 3 else None
        return 4 + int.from_bytes(buf[:4], "big") if len(buf) >= 4 else None

    def _receive(self) -> None:
        fd = self.stream.fileno()
        buf, offset = bytearray(), 0
        with selectors.DefaultSelector() as sel:
            try:
                sel.register(fd, selectors.EVENT_READ)
                ready: Any = lambda: sel.select(POLL_S)  # noqa: E731
            except PermissionError:  # a regular file (`live --stdin raw < rec.ast`):
                ready = lambda: True  # noqa: E731 - always readable; epoll refuses files
            while not self.stop.is_set():
                if not ready():
                    continue
                chunk = os.read(fd, 1 << 16)
                if not chunk:
                    break
                buf += chunk
                now = time.time()
                while (n := self._length(buf)) is not None and len(buf) >= n:
                    if self.framing == "raw" and n < 3:
                        raise ValueError(f"{self.name}, byte {offset}: data block length "
                                         f"{n} is below 3")
                    data = bytes(buf[:n] if self.framing == "raw" else buf[4:n])
                    self._put(data, now, self.name)
                    del buf[:n]
                    offset += n
        if buf and not self.stop.is_set():
            raise ValueError(f"{self.name}, byte {offset}: the stream ends inside a "
                             f"datagram ({len(buf)} bytes of it)")


@contextlib.contextmanager
def stop_on_signals(stop: threading.Event) -> Iterator[threading.Event]:
    """While inside, SIGTERM and SIGINT (Ctrl-C) set ``stop`` instead of ending the
    process; a second signal ends it as before. The previous handlers come back on
    exit. From the main thread only (elsewhere: no handler is installed)."""
    previous: dict[int, Any] = {}

    def handler(signum: int, frame: Any) -> None:
        if stop.is_set():  # a second Ctrl-C: give up at once
            raise KeyboardInterrupt if signum == signal.SIGINT else SystemExit(128 + signum)
        stop.set()

    if threading.current_thread() is threading.main_thread():
        for signum in (signal.SIGTERM, signal.SIGINT):
            previous[signum] = signal.signal(signum, handler)
    try:
        yield stop
    finally:
        for signum, h in previous.items():
            signal.signal(signum, h)
