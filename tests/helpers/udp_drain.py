"""What a test's loopback UDP socket holds, read without waiting."""

from __future__ import annotations

import socket


def drain(sock: socket.socket) -> list[bytes]:
    """Every datagram ``sock`` holds now, in arrival order (non-blocking reads)."""
    sock.setblocking(False)
    got = []
    while True:
        try:
            got.append(sock.recv(65535))
        except BlockingIOError:
            return got
