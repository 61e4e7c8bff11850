"""The network and stdin readers (:mod:`mhtrack.sources.udp`): every datagram sent to
loopback comes out once, with a receive time between its sending and its reading, from
several sockets merged; stdin framings split a byte stream back into the datagrams
written; a stop signal ends the reading cleanly."""

from __future__ import annotations

import io
import os
import signal
import socket
import threading
import time
from collections import Counter

import pytest

from mhtrack.sources.udp import (
    Endpoint,
    StdinReader,
    UdpReader,
    parse_endpoint,
    stop_on_signals,
)


def test_endpoints_parse() -> None:
    assert parse_endpoint("udp://127.0.0.1:8600") == Endpoint("127.0.0.1", 8600)
    ep = parse_endpoint("udp://[::1]:0")
    assert (ep.host, ep.port, ep.family) == ("::1", 0, socket.AF_INET6)
    assert str(ep) == "udp://[::1]:0"
    assert parse_endpoint("udp://232.1.1.1:8600").multicast
    assert not parse_endpoint("udp://127.0.0.1:1").multicast
    for bad in ("tcp://127.0.0.1:1", "udp://127.0.0.1", "udp://:5", "udp://h:99999",
                "udp://h:1/path"):
        with pytest.raises(ValueError, match="udp://HOST:PORT"):
            parse_endpoint(bad)


def _send(port: int, payloads: list[bytes], family: int = socket.AF_INET,
          host: str = "127.0.0.1") -> None:
    with socket.socket(family, socket.SOCK_DGRAM) as s:
        for p in payloads:
            s.sendto(p, (host, port))


def test_two_lans_merged_every_datagram_once() -> None:
    reader = UdpReader(["udp://127.0.0.1:0", "udp://127.0.0.1:0"])
    a = [b"A%04d" % i for i in range(300)]
    b = [b"B%04d" % i for i in range(200)]
    before = time.time()
    reader.start()
    _send(reader.addresses[0][1], a)
    _send(reader.addresses[1][1], b)
    reader.stop.set()  # loopback delivered every datagram at sendto: the stop drains them
    got = list(reader)
    after = time.time()
    assert Counter(d for d, _ in got) == Counter(a + b)
    assert [d for d, _ in got if d[:1] == b"A"] == a  # one socket keeps its order
    assert all(before <= t <= after for _, t in got)
    assert [t for _, t in got] == sorted(t for _, t in got)  # arrival order
    s = reader.stats
    assert (s.datagrams, s.bytes, s.queue_dropped) == (500, 5 * 500, 0)
    assert sorted(s.per_input.values()) == [200, 300]


def test_two_lans_read_in_turn() -> None:
    """The kernel holds 400 copies on each of two LANs (sent as a replay sends them: each
    datagram to one, then to the other) before the reader looks: it reads them in turn,
    so neither LAN's copies fall behind the other's by more than one (one socket emptied
    first put one LAN 400 datagrams behind)."""
    reader = UdpReader(["udp://127.0.0.1:0", "udp://127.0.0.1:0"])
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for i in range(400):
            for k in (0, 1):
                s.sendto(b"%d%04d" % (k, i), ("127.0.0.1", reader.addresses[k][1]))
    reader.stop.set()  # the stop reads what the kernel holds, then ends
    got = [d for d, _ in reader]
    assert len(got) == 800
    lag = [abs(sum(d[:1] == b"0" for d in got[:n]) - sum(d[:1] == b"1" for d in got[:n]))
           for n in range(len(got) + 1)]
    assert max(lag) <= 1
    assert [d for d in got if d[:1] == b"1"] == [b"1%04d" % i for i in range(400)]


def test_ipv6_loopback() -> None:
    try:
        reader = UdpReader(["udp://[::1]:0"])
    except OSError:
        pytest.skip("no IPv6 loopback here")
    reader.start()
    _send(reader.addresses[0][1], [b"x", b"yz"], socket.AF_INET6, "::1")
    reader.stop.set()
    assert [d for d, _ in reader] == [b"x", b"yz"]


def test_a_full_queue_counts_its_drops() -> None:
    reader = UdpReader(["udp://127.0.0.1:0"], max_queued=10)
    reader.start()
    _send(reader.addresses[0][1], [bytes([i]) for i in range(25)])
    reader.stop.set()
    reader._thread.join()
    got = [d for d, _ in reader]
    assert got == [bytes([i]) for i in range(10)]
    assert (reader.stats.datagrams, reader.stats.queue_dropped) == (10, 15)


def test_kernel_drops_counted_from_the_socket() -> None:
    """A socket with a small receive buffer, sent 300 datagrams of 1 000 octets over
    loopback before it is read (loopback delivers at ``sendto``: what the buffer cannot
    hold the kernel drops), then one more once it is read: every datagram sent is either
    received or in the kernel's drop count (``SO_RXQ_OVFL``), and some were dropped."""
    reader = UdpReader(["udp://127.0.0.1:0"], rcvbuf=4096)
    if reader.stats.kernel_dropped is None:
        reader.close()
        pytest.skip("SO_RXQ_OVFL not available (Linux only)")
    port = reader.addresses[0][1]
    _send(port, [b"%04d" % i + bytes(996) for i in range(300)])
    reader._drain()  # what the buffer held (read in this thread: no timing involved)
    _send(port, [b"last"])  # into an empty buffer; carries the count of every drop
    reader._drain()
    reader.stop.set()
    got = [d for d, _ in reader]
    assert got[-1] == b"last"
    assert 0 < reader.stats.kernel_dropped < 300
    assert len(got) + reader.stats.kernel_dropped == 301
    assert [int(d[:4]) for d in got[:-1]] == sorted(int(d[:4]) for d in got[:-1])


def test_kernel_drops_not_available_say_so(monkeypatch: pytest.MonkeyPatch) -> None:
    """Where the option does not exist the count is ``None`` (the status says n/a), not
    a zero that would claim no drops."""
    import mhtrack.sources.udp as udp

    monkeypatch.setattr(udp.sys, "platform", "darwin")
    reader = UdpReader(["udp://127.0.0.1:0"])
    reader.close()
    assert reader.stats.kernel_dropped is None
    assert StdinReader(io.BytesIO(b"")).stats.kernel_dropped is None


def test_a_quiet_input_yields_idle_once_per_quiet_spell() -> None:
    """With ``idle_s`` the reader yields ``IDLE`` once the clock (the test's own, one
    second a reading) has run ``idle_s`` past the last datagram, once per quiet spell,
    in its place between the datagrams; without it, never."""
    from mhtrack.sources.base import IDLE

    ticks = iter(range(10**6))
    r, w = os.pipe()
    with os.fdopen(r, "rb", buffering=0) as rf:
        reader = StdinReader(rf, framing="len32", idle_s=3.0,
                             clock=lambda: float(next(ticks)))
        it = iter(reader)
        os.write(w, b"\0\0\0\1a")
        assert next(it)[0] == b"a"
        assert next(it) is IDLE and reader.idles == 1  # quiet: the clock ran on
        os.write(w, b"\0\0\0\1b")
        assert next(it)[0] == b"b"  # quiet again after it, one more IDLE
        assert next(it) is IDLE and reader.idles == 2
        os.write(w, b"\0\0\0\1c")
        os.close(w)
        rest = list(it)
    assert [x[0] for x in rest if x is not IDLE] == [b"c"]
    r, w = os.pipe()
    os.write(w, b"\0\0\0\1a")
    os.close(w)
    with os.fdopen(r, "rb", buffering=0) as rf:
        plain = StdinReader(rf, framing="len32")
        assert [d for d, _ in plain] == [b"a"] and plain.idles == 0
    with pytest.raises(ValueError, match="idle_s"):
        StdinReader(io.BytesIO(b""), idle_s=0.0)


def _blocks() -> list[bytes]:
    """Three ASTERIX-framed blocks (category, 2-octet length, bytes)."""
    return [bytes([48, 0, 5, 1, 2]), bytes([34, 0, 3]), bytes([62, 0, 9]) + b"abcdef"]


@pytest.mark.parametrize("framing", ["raw", "len32"])
def test_stdin_framings(framing: str) -> None:
    blocks = _blocks() * 50
    stream = b"".join(b if framing == "raw" else len(b).to_bytes(4, "big") + b
                      for b in blocks)
    r, w = os.pipe()
    with os.fdopen(r, "rb", buffering=0) as rf:
        writer = threading.Thread(target=lambda: (os.write(w, stream), os.close(w)))
        writer.start()
        got = [d for d, _ in StdinReader(rf, framing=framing)]
        writer.join()
    assert got == blocks


def test_stdin_from_a_regular_file(tmp_path) -> None:
    """``live --stdin raw < rec.ast``: epoll refuses a regular file; it is read as is."""
    blocks = _blocks() * 20
    (tmp_path / "rec.ast").write_bytes(b"".join(blocks))
    with (tmp_path / "rec.ast").open("rb", buffering=0) as f:
        assert [d for d, _ in StdinReader(f, framing="raw")] == blocks


def test_stdin_ending_inside_a_datagram_names_the_byte() -> None:
    r, w = os.pipe()
    os.write(w, _blocks()[0] + bytes([48, 0, 9, 1]))
    os.close(w)
    with os.fdopen(r, "rb", buffering=0) as rf:
        reader = StdinReader(rf, framing="raw")
        with pytest.raises(ValueError, match="stdin, byte 5: the stream ends inside a "
                           r"datagram \(4 bytes of it\)"):
            list(reader)


def test_sigterm_sets_the_stop_and_the_handler_comes_back() -> None:
    before = signal.getsignal(signal.SIGTERM)
    with stop_on_signals(threading.Event()) as stop:
        reader = UdpReader(["udp://127.0.0.1:0"], stop=stop)
        reader.start()
        _send(reader.addresses[0][1], [b"one", b"two"])
        os.kill(os.getpid(), signal.SIGTERM)  # the process lives on; the reading ends
        got = [d for d, _ in reader]
        assert stop.is_set()
    assert got == [b"one", b"two"]
    assert signal.getsignal(signal.SIGTERM) is before


MULTICAST = """
import socket
from mhtrack.sources.udp import UdpReader
r = UdpReader(["udp://239.1.2.3:0"])
r.start()
with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
    for i in range(50):
        s.sendto(b"m%d" % i, ("239.1.2.3", r.addresses[0][1]))
r.stop.set()
print(",".join(d.decode() for d, _ in r))
"""


def test_multicast_group_in_a_network_namespace_of_its_own() -> None:
    """A multicast group joined and received — only inside a network namespace the test
    makes (``unshare -n``, root), with just its loopback up: nothing leaves the host."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    if os.geteuid() != 0 or shutil.which("unshare") is None or shutil.which("ip") is None:
        pytest.skip("needs root, unshare and ip for a network namespace")
    src = str(Path(__file__).resolve().parents[2] / "src")
    setup = ("ip link set lo up && ip link set lo multicast on && "
             "ip route add 224.0.0.0/4 dev lo && exec \"$0\" -c \"$1\"")
    done = subprocess.run(["unshare", "-n", "sh", "-c", setup, sys.executable, MULTICAST],
                          capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": src})
    if done.returncode != 0 and "unshare" in done.stderr and "ermission" in done.stderr:
        pytest.skip(f"no network namespace here: {done.stderr.strip()}")
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == ",".join(f"m{i}" for i in range(50))
