"""A raw stream of CAT001/002/021 blocks: each block judged (its records fill it) and
decoded from one libasterix parse, and the plots the same as the same blocks read from a
pcap, where no block is judged (the former path)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix")

import asterix.base as base

from mhtrack.io.asterix import encode_other, read_recording, wrap


def _blocks() -> list[tuple[float, int, bytes]]:
    """Radar 513's CAT001 plots with CAT002 north marks every 4 s, and ADS-B station
    0x0102's CAT021 reports, over 40 s."""
    rng = np.random.default_rng(5)
    t = np.sort(rng.uniform(1000.0, 1040.0, 60))
    msgs = [(float(t[i]), 513, 1, encode_other.plot001(
        t[i], 513, rng.uniform(1e3, 2e5), rng.uniform(0, 360), fl=float(i)))
        for i in range(t.size)]
    msgs += [(float(m), 513, 2, encode_other.mark002(m, 513, 1, period=4.0))
             for m in np.arange(998.0, 1040.0, 4.0)]
    msgs += [(float(t[i]) + 0.1, 0x0102, 21, encode_other.report021(
        t[i] + 0.1, 0x0102, 46.0 + i * 1e-3, 7.0, address=f"{0xABC000 + i:06X}"))
        for i in range(0, t.size, 2)]
    return encode_other.blocks(msgs)


def test_raw_blocks_parsed_once_with_the_plots_of_the_pcap(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    got = _blocks()
    raw, pcap = tmp_path / "r.ast", tmp_path / "r.pcap"
    raw.write_bytes(b"".join(b for _, _, b in got))
    pcap.write_bytes(wrap.pcap(wrap.udp_frames([b for _, _, b in got], 513),
                               [t for t, _, _ in got]))
    parses = [0]
    from_bytes = base.Bits.from_bytes

    def counted(octets: bytes) -> base.Bits:
        parses[0] += 1
        return from_bytes(octets)

    monkeypatch.setattr(base.Bits, "from_bytes", counted)
    r = read_recording(raw)
    assert parses[0] == len(got)  # one parse a block: judged and decoded from it
    parses[0] = 0
    p = read_recording(pcap)
    assert parses[0] == len(got)  # a pcap's blocks are not judged: decoded only
    assert not r.problems.counts and not p.problems.counts
    assert r.plots.keys() == p.plots.keys() and r.plots["time"].size == 90
    for k, v in p.plots.items():
        assert np.array_equal(r.plots[k], v, equal_nan=v.dtype.kind == "f"), k
    assert set(r.plots["plot_type"].tolist()) == {3, 5}  # CAT001 combined, ADS-B
    for k, v in p.sweeps.items():
        assert np.array_equal(r.sweeps[k], v, equal_nan=v.dtype.kind == "f"), k
