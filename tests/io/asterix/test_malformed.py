"""Malformed recordings: each kind of damage is skipped and counted (one warning line per
kind) or refused with the byte offset; the good plots of the file are kept."""

from __future__ import annotations

import logging
import struct
from pathlib import Path

import numpy as np
import pytest
from tests.helpers.plot_blocks import plot_blocks

from mhtrack.errors import InputError
from mhtrack.io.asterix import read_recording
from mhtrack.io.asterix.writer import datagram

N_BLOCKS, PER_BLOCK = 6, 5


def _blocks() -> list[bytes]:
    """Six CAT048 blocks of five plots each, from radar SAC 1 / SIC 2."""
    return plot_blocks(N_BLOCKS, PER_BLOCK)


def _pcap(frames: list[bytes]) -> bytes:
    head = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)
    return head + b"".join(struct.pack("<IIII", i, 0, len(f), len(f)) + f
                           for i, f in enumerate(frames))


def _read(tmp_path: Path, name: str, data: bytes):  # type: ignore[no-untyped-def]
    path = tmp_path / name
    path.write_bytes(data)
    return read_recording(path)


def test_clean_files(tmp_path: Path) -> None:
    blocks = _blocks()
    for name, data in (("a.ast", b"".join(blocks)),
                       ("a.pcap", _pcap([datagram(b, 258, i) for i, b in enumerate(blocks)]))):
        rec = _read(tmp_path, name, data)
        assert len(rec) == N_BLOCKS * PER_BLOCK and not rec.problems.counts


def test_truncated_block_raw(tmp_path: Path) -> None:
    blocks = _blocks()
    data = b"".join(blocks)[:-7]  # the last block cut short
    rec = _read(tmp_path, "cut.ast", data)
    assert len(rec) == (N_BLOCKS - 1) * PER_BLOCK
    at = sum(map(len, blocks[:-1]))  # the raw stream's last record is damaged
    assert rec.problems.counts == {"resync": 1, "skipped_octets": len(data) - at}
    assert rec.problems.first["resync"] == at


def test_truncated_pcap_packet(tmp_path: Path) -> None:
    frames = [datagram(b, 258, i) for i, b in enumerate(_blocks())]
    data = _pcap(frames)
    rec = _read(tmp_path, "cut.pcap", data[:-10])
    assert len(rec) == (N_BLOCKS - 1) * PER_BLOCK
    at = len(data) - 16 - len(frames[-1])  # the last packet record
    assert rec.problems.counts == {"resync": 1, "skipped_octets": len(data) - 10 - at}
    assert rec.problems.first["resync"] == at


@pytest.mark.parametrize("delta", [+4, -2])
def test_block_length_disagrees_with_data(tmp_path: Path, delta: int) -> None:
    blocks = _blocks()
    bad = bytearray(blocks[2])
    bad[1:3] = (len(bad) + delta).to_bytes(2, "big")  # length field wrong
    frames = [datagram(bytes(bad) if i == 2 else b, 258, i) for i, b in enumerate(blocks)]
    rec = _read(tmp_path, "len.pcap", _pcap(frames))
    assert len(rec) == (N_BLOCKS - 1) * PER_BLOCK  # only that block's plots are lost
    kind = "truncated_block" if delta > 0 else "undecodable"
    assert rec.problems.counts[kind] == 1


def test_unknown_category_skipped(tmp_path: Path) -> None:
    blocks = _blocks()
    cat62 = bytes([62, 0, 6, 0x80, 0x19, 0xC8])  # a CAT062 block: not read
    data = b"".join(blocks[:3]) + cat62 + b"".join(blocks[3:])
    rec = _read(tmp_path, "cat.ast", data)
    assert len(rec) == N_BLOCKS * PER_BLOCK
    assert rec.problems.counts == {"unknown_category": 1}
    assert "category 62" in rec.problems.lines("cat.ast")[0]


def test_random_bytes_refused(tmp_path: Path) -> None:
    data = np.random.default_rng(5).integers(0, 256, 4000, dtype=np.uint8).tobytes()
    data = b"\x00" + data  # category 0 does not exist
    with pytest.raises(InputError, match=r"rand\.bin: byte 0: not an ASTERIX recording"):
        _read(tmp_path, "rand.bin", data)


def test_random_bytes_after_good_blocks(tmp_path: Path) -> None:
    blocks = _blocks()
    junk = bytes([48, 0, 2]) + b"\xff" * 50  # a block header with length 2: stream lost
    rec = _read(tmp_path, "tail.ast", b"".join(blocks) + junk)
    assert len(rec) == N_BLOCKS * PER_BLOCK
    assert rec.problems.counts == {"resync": 1, "skipped_octets": len(junk)}
    assert rec.problems.first["resync"] == sum(map(len, blocks))


def test_non_udp_packets_skipped(tmp_path: Path) -> None:
    blocks = _blocks()
    arp = bytes(12) + b"\x08\x06" + bytes(28)
    udp = datagram(blocks[0], 258, 1)
    tcp = bytearray(udp)
    tcp[14 + 9] = 6  # IPv4 protocol TCP
    frames = [arp] + [datagram(b, 258, i) for i, b in enumerate(blocks)] + [bytes(tcp)]
    rec = _read(tmp_path, "mixed.pcap", _pcap(frames))
    assert len(rec) == N_BLOCKS * PER_BLOCK
    assert rec.problems.counts == {"non_udp": 2}
    assert rec.problems.first["non_udp"] == 24  # the first packet record


def test_one_warning_line_per_kind(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    blocks = _blocks()
    cat62 = bytes([62, 0, 6, 0x80, 0x19, 0xC8])
    data = cat62 + b"".join(blocks) + cat62 + blocks[0][:-3]
    rec = _read(tmp_path, "two.ast", data)
    with caplog.at_level(logging.WARNING, logger="mhtrack"):
        rec.problems.warn("two.ast")
    lines = [r.getMessage() for r in caplog.records]
    assert len(lines) == 3
    assert "2 data block(s) of categories not read here" in lines[0]
    assert "(first at byte 0; category 62)" in lines[0]
    at = 2 * len(cat62) + sum(map(len, blocks))
    assert lines[1] == f"two.ast: 1 damaged framing record(s) or packet(s): reading went " \
        f"on at the next valid one (first at byte {at})"
    assert lines[2].startswith(f"two.ast: {len(blocks[0]) - 3} octet(s) of damaged framing")
