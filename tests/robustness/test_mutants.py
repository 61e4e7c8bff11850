"""Damaged recordings through ``convert`` and ``track`` (issue 33; the 2 000-mutant run is
``benchmarks/mutants.py``, whose definitions these follow).

A packet (a pcap record, a pcapng block, a raw data block) is *touched* when the damage
changes one of its octets. Property, for seeded bit flips, truncations, inserted and
deleted octets, splices, duplicated and swapped packets of a pcap, a pcapng
recording and of a raw stream of data blocks: ``convert`` and ``track`` end with status 0
(status 2, one line, only when the file's own header is damaged), and every plot of
every untouched packet is in ``convert``'s output (raw blocks are judged by their
content, so a damaged length no longer takes the good blocks it covers). Derandomised,
so that CI is repeatable.
"""

from __future__ import annotations

import collections
import random
import struct
from pathlib import Path
from typing import Any

import pyarrow.csv as pacsv
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mhtrack.cli.main import cli

pytest.importorskip("asterix")

from mhtrack.io.asterix import wrap
from mhtrack.io.asterix.decode import PLOT_COLUMNS, Decoder
from mhtrack.io.asterix.framings import recognise, units
from mhtrack.io.asterix.problems import Problems

MUTANTS = settings(derandomize=True, deadline=None, max_examples=40, database=None,
                   suppress_health_check=[HealthCheck.function_scoped_fixture,
                                          HealthCheck.too_slow])
KEY = ("sensor", "slant_range", "bearing", "time")
KINDS = ("bitflip", "truncate", "insert", "delete", "splice", "duplicate", "swap")


def _spans(fmt: str, data: bytes) -> tuple[int, list[tuple[int, int]]]:
    """(end of the file's own header, each packet's span)."""
    out, p = [], {"pcap": 24, "pcapng": 0, "raw": 0}[fmt]
    while p < len(data):
        if fmt == "pcap":
            e = p + 16 + struct.unpack_from("<I", data, p + 8)[0]
        elif fmt == "pcapng":
            e = p + struct.unpack_from("<I", data, p + 4)[0]
        else:
            e = p + ((data[p + 1] << 8) | data[p + 2])
        out.append((p, e))
        p = e
    if fmt == "pcapng":  # section header and interface description
        return out[1][1], out[2:]
    return (24 if fmt == "pcap" else 0), out


def _plots(data: bytes, spans: list[tuple[int, int]]) -> list[list[tuple[float, ...]]]:
    """Each packet's plots (sensor, slant range, bearing, time of day) as decoded from
    the undamaged file."""
    decoder, problems = Decoder(), Problems()
    kind = recognise(data, "base", decoder.categories)
    out: list[list[tuple[float, ...]]] = [[] for _ in spans]
    idx = [PLOT_COLUMNS.index(k) for k in KEY[:3]]
    for offset, when, payload in units(data, kind, "base", decoder.categories, problems):
        for at, what, found in decoder.blocks(payload, offset, problems, when):
            if what == "plots":
                i = next(i for i, (s, e) in enumerate(spans) if s <= at < e)
                out[i] += [(*(float(r[j]) for j in idx), float(r[0]) % 86400)
                           for r in found]
    assert not problems.counts
    return out


@pytest.fixture(scope="module")
def bases(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("mutants")
    runner = CliRunner()
    assert runner.invoke(cli, ["simulate", "opensky-radars", "--seed", "1", "--scans", "3",
                               "--out", str(d)]).exit_code == 0
    assert runner.invoke(cli, ["export", str(d / "plots.csv"), "--sensors",
                               str(d / "sensors.toml"), "--out",
                               str(d / "rec.pcap")]).exit_code == 0
    pcap = (d / "rec.pcap").read_bytes()
    _, sp = _spans("pcap", pcap)
    frames = [pcap[s + 16:e] for s, e in sp]
    times = [a + b * 1e-6 for a, b in (struct.unpack_from("<II", pcap, s) for s, _ in sp)]
    out: dict[str, Any] = {"dir": d}
    for fmt, data in (("pcap", pcap), ("pcapng", wrap.pcapng(frames, times)),
                      ("raw", b"".join(f[42:] for f in frames))):
        header, spans = _spans(fmt, data)
        out[fmt] = (data, header, spans, _plots(data, spans))
    return out


def _mutate(data: bytes, header: int, spans: list[tuple[int, int]], kind: str,
            rng: random.Random) -> tuple[bytes, set[int], bool]:
    """(damaged octets, touched packets, header touched)."""
    n = len(data)

    def region(a: int, b: int, new: bytes) -> tuple[bytes, set[int], bool]:
        if a == b:
            return (data[:a] + new + data[a:], {i for i, (s, e) in enumerate(spans)
                                                if s < a < e}, 0 < a < header)
        return (data[:a] + new + data[b:], {i for i, (s, e) in enumerate(spans)
                                            if s < b and a < e}, a < header)

    if kind == "bitflip":
        a = rng.randrange(n)
        return region(a, a + 1, bytes([data[a] ^ (1 << rng.randrange(8))]))
    if kind == "truncate":
        return region(rng.randrange(header, n), n, b"")
    if kind == "insert":
        return region(a := rng.randrange(n + 1), a, rng.randbytes(rng.randint(1, 64)))
    if kind == "delete":
        a = rng.randrange(n)
        return region(a, min(n, a + rng.randint(1, 64)), b"")
    if kind == "splice":
        a, c = rng.randrange(n), rng.randrange(n)
        return region(a, min(n, a + rng.randint(1, 200)), data[c:c + rng.randint(1, 200)])
    i = rng.randrange(len(spans) - 1)
    (s, e), (t, u) = spans[i], spans[i + 1]
    if kind == "duplicate":
        at = spans[min(len(spans) - 1, i + rng.randint(0, 20))][1]
        return data[:at] + data[s:e] + data[at:], set(), False
    return data[:s] + data[t:u] + data[s:e] + data[u:], set(), False


@MUTANTS
@given(fmt=st.sampled_from(["pcap", "pcapng", "raw"]), kind=st.sampled_from(KINDS),
       seed=st.integers(0, 2**32 - 1))
def test_a_damaged_recording_keeps_every_plot_of_its_untouched_packets(
        bases: dict[str, Any], fmt: str, kind: str, seed: int) -> None:
    data, header, spans, plots = bases[fmt]
    damaged, touched, head = _mutate(data, header, spans, kind, random.Random(seed))
    d: Path = bases["dir"]
    path = d / f"m.{'ast' if fmt == 'raw' else fmt}"
    path.write_bytes(damaged)
    kept = [k for i, keys in enumerate(plots) if i not in touched for k in keys]
    runner = CliRunner()
    res = runner.invoke(cli, ["convert", str(path), str(d / "c.csv")])
    allowed = {0, 2} if head or not kept else {0}
    assert res.exit_code in allowed and not (res.exception and res.exit_code == 1), \
        res.output
    if res.exit_code == 0 and not head:
        t = pacsv.read_csv(d / "c.csv").to_pydict()
        got = collections.Counter(zip(*(map(float, t[k]) for k in KEY[:3]),
                                      (float(x) % 86400 for x in t["time"]), strict=True))
        assert not collections.Counter(kept) - got
    res = runner.invoke(cli, ["track", str(path), "--sensors", str(d / "sensors.toml"),
                              "--out", str(d / "t.csv")])
    assert res.exit_code in allowed and not (res.exception and res.exit_code == 1), \
        res.output
