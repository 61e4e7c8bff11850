"""Sinks that send every frame's output at once (``docs/live.md``): CAT062 data blocks
over UDP (:class:`Cat062UdpSink`) and JSON lines on a text stream (:class:`JsonLinesSink`).

Both take the frame's online rows only — what the tracker reports at that frame (the
backfill of newly confirmed tracks is history, not news): a live consumer sees each
frame's system tracks as soon as the frame is stepped.
"""

from __future__ import annotations

import json
import math
import socket
from typing import TYPE_CHECKING, TextIO

import numpy as np

from mhtrack.sinks.base import FrameOutput, Sink
from mhtrack.sinks.files import cat062_blocks
from mhtrack.sources.udp import Endpoint, parse_endpoint

if TYPE_CHECKING:
    from mhtrack.models.geodesy import LocalFrame


class Cat062UdpSink(Sink):
    """Each frame's online rows as CAT062 data blocks (:func:`cat062_blocks`, the
    encoder of :class:`~mhtrack.sinks.Cat062Sink`), one data block per datagram, sent to
    ``udp://HOST:PORT`` (unicast, or a multicast group with ``ttl`` hops; IPv6 in
    brackets). A frame with no online rows sends nothing. :attr:`datagrams` and
    :attr:`rows` count what was sent."""

    def __init__(self, to: str | Endpoint, frame: LocalFrame, *, sac: int | None = None,
                 sic: int | None = None, ttl: int = 1) -> None:
        self.to = to if isinstance(to, Endpoint) else parse_endpoint(to)
        self.frame, self.sac, self.sic, self.ttl = frame, sac, sic, ttl
        self.datagrams = self.rows = 0
        self._sock: socket.socket | None = None
        self._addr: tuple[str, int] | None = None

    def start(self, source: object) -> None:
        ep = self.to
        info = socket.getaddrinfo(ep.host, ep.port, ep.family, socket.SOCK_DGRAM)
        self._addr = info[0][4][:2]
        self._sock = socket.socket(ep.family, socket.SOCK_DGRAM)
        if ep.multicast:
            level, opt = ((socket.IPPROTO_IPV6, socket.IPV6_MULTICAST_HOPS)
                          if ep.family == socket.AF_INET6
                          else (socket.IPPROTO_IP, socket.IP_MULTICAST_TTL))
            self._sock.setsockopt(level, opt, self.ttl)

    def write(self, out: FrameOutput) -> None:
        if len(out.online) == 0:
            return
        if self._sock is None:
            self.start(None)
        assert self._sock is not None and self._addr is not None
        for _, _, block in cat062_blocks(out.online, self.frame, str(self.to), sac=self.sac,
                                         sic=self.sic):
            self._sock.sendto(block, self._addr)
            self.datagrams += 1
        self.rows += len(out.online)

    def close(self) -> None:
        if self._sock is not None:
            self._sock.close()
            self._sock = None


def _num(v: float, digits: int = 3) -> float | None:
    return None if not math.isfinite(v) else round(v, digits)


class JsonLinesSink(Sink):
    """One JSON object per online row, a line each, flushed after every frame:
    ``frame, time, track_id, x, y, vx, vy`` (the local frame, m and m/s, to 1 mm; time
    to 1 µs), ``lat, lon``
    (with a ``frame``), ``coasting`` (no plot this frame) and ``tentative``. ``label``
    names the first field: ``frame`` on update, ``tick`` for the ticks of
    :class:`~mhtrack.sinks.periodic.PeriodicSink` (the tick's number)."""

    def __init__(self, stream: TextIO, frame: LocalFrame | None = None, *,
                 label: str = "frame") -> None:
        self.stream, self.frame, self.label = stream, frame, label

    def write(self, out: FrameOutput) -> None:
        t = out.online
        if len(t) == 0:
            return
        lat = lon = None
        if self.frame is not None:
            lat, lon = self.frame.to_geodetic(t.x, t.y)
        tent = np.zeros(len(t), bool) if t.tentative is None else t.tentative.astype(bool)
        for i in range(len(t)):
            row = {self.label: int(out.frame.index), "time": _num(float(t.time[i]), 6),
                   "track_id": int(t.track_id[i]), "x": _num(float(t.x[i])),
                   "y": _num(float(t.y[i])), "vx": _num(float(t.vx[i])),
                   "vy": _num(float(t.vy[i]))}
            if lat is not None and lon is not None:
                row["lat"], row["lon"] = round(float(lat[i]), 7), round(float(lon[i]), 7)
            row["coasting"] = bool(t.plot[i] < 0)
            row["tentative"] = bool(tent[i])
            self.stream.write(json.dumps(row) + "\n")
        self.stream.flush()
