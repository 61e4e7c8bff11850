"""Containers recognised by content: pcapng (either byte order), pcap link types (VLAN,
raw IP, Linux cooked), IPv6, whatever the file's name."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from mhtrack.errors import InputError
from mhtrack.io.asterix import read_recording
from mhtrack.io.asterix.encode import encode_blocks, plot_messages
from mhtrack.io.asterix.writer import datagram


def _blocks() -> list[bytes]:
    msgs = plot_messages(np.arange(6.0), np.full(6, 513), np.full(6, 5e4),
                         np.arange(6) * 10.0, {})
    return [b for _, _, b in encode_blocks(msgs[:3])] + \
        [b for _, _, b in encode_blocks(msgs[3:])]


def _pad(b: bytes) -> bytes:
    return b + bytes(-len(b) % 4)


def _pcapng(frames: list[bytes], e: str = "<", link: int = 1) -> bytes:
    shb_body = struct.pack(e + "IHHq", 0x1A2B3C4D, 1, 0, -1)
    out = struct.pack(e + "II", 0x0A0D0D0A, 12 + len(shb_body)) + shb_body + \
        struct.pack(e + "I", 12 + len(shb_body))
    idb = struct.pack(e + "HHI", link, 0, 65535)
    out += struct.pack(e + "II", 1, 12 + len(idb)) + idb + struct.pack(e + "I", 12 + len(idb))
    for f in frames:
        body = struct.pack(e + "IIIII", 0, 0, 0, len(f), len(f)) + _pad(f)
        out += struct.pack(e + "II", 6, 12 + len(body)) + body + \
            struct.pack(e + "I", 12 + len(body))
    return out


def _pcap(frames: list[bytes], link: int) -> bytes:
    head = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, link)
    return head + b"".join(struct.pack("<IIII", 0, 0, len(f), len(f)) + f for f in frames)


@pytest.mark.parametrize("order", ["<", ">"])
def test_pcapng(tmp_path: Path, order: str) -> None:
    path = tmp_path / "capture.dat"  # the name says nothing
    path.write_bytes(_pcapng([datagram(b, 513, i) for i, b in enumerate(_blocks())], order))
    rec = read_recording(path)
    assert rec.container == "pcapng"
    assert len(rec) == 6 and np.array_equal(rec.plots["sic"], np.full(6, 1))
    assert np.allclose(rec.plots["bearing"], np.arange(6) * 10.0, atol=0.003)


def test_link_types_and_ipv6(tmp_path: Path) -> None:
    blocks = _blocks()
    eth = [datagram(b, 513, i) for i, b in enumerate(blocks)]
    vlan = [f[:12] + b"\x81\x00\x00\x05" + f[12:] for f in eth]
    raw_ip = [f[14:] for f in eth]
    sll = [bytes(14) + b"\x08\x00" + f[14:] for f in eth]
    udp = [f[34:] for f in eth]
    ipv6 = [bytes(12) + b"\x86\xdd" + struct.pack("!IHBB", 6 << 28, len(u), 17, 64)
            + bytes(32) + u for u in udp]
    for name, frames, link in (("vlan", vlan, 1), ("raw", raw_ip, 101), ("sll", sll, 113),
                               ("v6", ipv6, 1)):
        path = tmp_path / f"{name}.bin"
        path.write_bytes(_pcap(frames, link))
        rec = read_recording(path)
        assert len(rec) == 6, name
        assert not rec.problems.counts, name


def test_unknown_link_type_refused(tmp_path: Path) -> None:
    path = tmp_path / "wifi.pcap"
    path.write_bytes(_pcap([datagram(b, 513, 0) for b in _blocks()], 105))
    with pytest.raises(InputError, match=r"byte 20: capture link type 105 is not read"):
        read_recording(path)


def test_empty_file_refused(tmp_path: Path) -> None:
    path = tmp_path / "empty.ast"
    path.write_bytes(b"")
    with pytest.raises(InputError, match=r"byte 0: not an ASTERIX recording \(the file is "
                       "empty"):
        read_recording(path)


def test_is_recording_by_content(tmp_path: Path) -> None:
    from mhtrack.io.asterix import is_recording

    raw = tmp_path / "feed.dat"
    raw.write_bytes(b"".join(_blocks()))
    text = tmp_path / "notes.txt"
    text.write_text("time,sensor\n" + "0.5,1\n" * 20000)  # 120 kB of text
    table = tmp_path / "plots.csv"
    table.write_bytes(b"".join(_blocks()))  # a table by its name, whatever it holds
    assert is_recording(raw)
    assert not is_recording(text) and not is_recording(table)


def test_every_framing_is_a_recording_by_content(tmp_path: Path) -> None:
    """GPS, Final, ORADIS, pcapng and 802.3/LLC captures under a name that says nothing
    (``.bin``) are recordings, each read back to the same plots."""
    from mhtrack.io.asterix import is_recording, wrap

    blocks = _blocks()
    times = [10.0 + k for k in range(len(blocks))]  # capture times of the same day
    files = {"gps": wrap.gps(blocks, times), "final": wrap.final(blocks, times),
             "oradis": wrap.oradis(blocks, times),
             "pcapng": wrap.pcapng(wrap.udp_frames(blocks, 513), times),
             "llc": wrap.pcap([wrap.llc_frame(b, 513) for b in blocks], times)}
    (tmp_path / "raw.ast").write_bytes(b"".join(blocks))
    ref = read_recording(tmp_path / "raw.ast")
    for kind, data in files.items():
        path = tmp_path / f"{kind}.bin"
        path.write_bytes(data)
        assert is_recording(path), kind
        rec = read_recording(path)
        assert rec.container == ("pcap" if kind == "llc" else kind)
        assert np.array_equal(rec.plots["slant_range"], ref.plots["slant_range"]), kind
        assert np.array_equal(rec.plots["time"], ref.plots["time"]), kind
