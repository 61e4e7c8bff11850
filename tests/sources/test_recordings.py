"""ASTERIX recordings as sources: the frames of the former path (decode, temporary Parquet,
``read_plots``: ``tests/reference/recording_table.py``) bit for bit; a packet arriving 40 s late
dropped with one warning; midnight and a 13-hour gap on a monotonic axis; errors naming
the user's file; any iterable of datagrams."""

from __future__ import annotations

import logging
import struct
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pyarrow.csv as pacsv
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from recording_table import recording_table

from mhtrack.errors import InputError
from mhtrack.io.asterix import export
from mhtrack.io.asterix.framings import units
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.sensors import read_sensors, write_sensors
from mhtrack.records import Scan
from mhtrack.sources import open_source
from mhtrack.sources.datagrams import DatagramSource
from mhtrack.sources.recording import AsterixSource

from .conftest import differences

PCAP_HEAD = 24
#: Offset of the ASTERIX data in a packet record: its header, Ethernet, IPv4, UDP.
UDP_DATA = 16 + 14 + 20 + 8


def _today(rec: Path, sensors: Path) -> tuple[list[Scan], np.ndarray]:
    """Frames and file rows by the former path (``tests/reference/recording_table.py``:
    decode, temporary Parquet, ``read_plots``)."""
    with tempfile.TemporaryDirectory() as tmp:
        table = recording_table(rec, read_sensors(sensors), Path(tmp))
        return list(table.scans()), table.file_row


def _frames(rec: Path, sensors: Path, **kw: object) -> tuple[list[Scan], AsterixSource]:
    src = open_source(rec, sensors=read_sensors(sensors), **kw)
    assert isinstance(src, AsterixSource)
    return list(src), src


@pytest.fixture(scope="module")
def recs(opensky2: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("recs")
    sensors = read_sensors(opensky2 / "sensors.toml")
    paths = {}
    for suffix in (".pcap", ".ast"):
        paths[suffix] = out / f"rec{suffix}"
        export(opensky2 / "plots.csv", sensors, paths[suffix])
    no_periods = replace(sensors, sensors=tuple(replace(s, period=None)
                                                for s in sensors.sensors))
    write_sensors(no_periods, out / "no_periods.toml")
    paths["no_periods"] = out / "no_periods.toml"
    return paths


@pytest.mark.parametrize("suffix", [".pcap", ".ast"])
def test_same_frames_as_today(opensky2: Path, recs: dict[str, Path], suffix: str) -> None:
    for sensors in (opensky2 / "sensors.toml", recs["no_periods"]):
        ref, file_row = _today(recs[suffix], sensors)
        got, src = _frames(recs[suffix], sensors)
        assert differences(ref, got) == [] and len(got) > 300
        rows = np.concatenate([s.rows for s in got])
        assert np.array_equal(src.file_rows(rows), file_row[rows])
        assert src.stats.late_dropped == 0 and src.stats.plots_out == rows.size
        assert src.container == suffix.strip(".").replace("ast", "raw")
    # periods from CAT034 (the file without periods) are the sensors file's
    assert {s.id: s.period for s in src.sensors.sensors} == {
        s.id: s.period for s in read_sensors(opensky2 / "sensors.toml").sensors}


def test_datagrams_from_anywhere(opensky2: Path, recs: dict[str, Path]) -> None:
    data = recs[".pcap"].read_bytes()
    grams = [(bytes(p), when) for _, when, p in units(data, "pcap", "x", {34, 48},
                                                       Problems())]
    sensors = read_sensors(opensky2 / "sensors.toml")
    ref, _ = _frames(recs[".pcap"], opensky2 / "sensors.toml")
    got = list(DatagramSource(grams, sensors=sensors, name="udp"))
    assert differences(ref, got) == []
    bare = list(DatagramSource((p for p, _ in grams), sensors=sensors))  # no capture times
    assert differences(ref, bare) == []


def test_datagrams_one_block_at_a_time(opensky2: Path, recs: dict[str, Path]) -> None:
    """``chunk=1`` (a live feed: each data block passed on as it arrives) gives the same
    frames, and the first frame leaves before the input is read to its end."""
    data = recs[".pcap"].read_bytes()
    grams = [bytes(p) for _, _, p in units(data, "pcap", "x", {34, 48}, Problems())]
    sensors = read_sensors(opensky2 / "sensors.toml")
    ref = list(DatagramSource(grams, sensors=sensors))
    read = [0]

    def feed():  # type: ignore[no-untyped-def]
        for g in grams:
            read[0] += 1
            yield g

    frames = iter(DatagramSource(feed(), sensors=sensors, chunk=1))
    first = next(frames)
    assert read[0] < 200 < len(grams)  # well before the end: a few sectors' datagrams
    assert differences(ref, [first, *frames]) == []


def _packets(data: bytes) -> list[tuple[float, bytes]]:
    """(capture time, record) of each packet of a microsecond pcap."""
    out, pos = [], PCAP_HEAD
    while pos < len(data):
        sec, usec, incl, _ = struct.unpack_from("<IIII", data, pos)
        out.append((sec + usec * 1e-6, data[pos:pos + 16 + incl]))
        pos += 16 + incl
    return out


def _stamp(record: bytes, when: float) -> bytes:
    usec = round(when * 1e6)
    return struct.pack("<II", usec // 1_000_000, usec % 1_000_000) + record[8:]


def test_packet_40_s_late(recs: dict[str, Path], opensky2: Path, tmp_path: Path,
                          caplog: pytest.LogCaptureFixture) -> None:
    """One CAT048 packet captured 40 s after it was sent: its plots are dropped (one
    warning line), the frames are those of the recording without it."""
    data = recs[".pcap"].read_bytes()
    pk = _packets(data)
    k = next(i for i, (_, r) in enumerate(pk) if i > 200 and r[UDP_DATA] == 48)
    to = next(i for i, (t, _) in enumerate(pk) if t > pk[k][0] + 40.0)
    moved = _stamp(pk[k][1], pk[to - 1][0])  # captured with the packets 40 s later
    late = [r for i, (_, r) in enumerate(pk[:to]) if i != k] + [moved] + \
        [r for _, r in pk[to:]]
    (tmp_path / "late.pcap").write_bytes(data[:PCAP_HEAD] + b"".join(late))
    (tmp_path / "without.pcap").write_bytes(
        data[:PCAP_HEAD] + b"".join(r for i, (_, r) in enumerate(pk) if i != k))
    with caplog.at_level(logging.WARNING, logger="mhtrack"):
        got, src = _frames(tmp_path / "late.pcap", opensky2 / "sensors.toml")
    ref, _ = _frames(tmp_path / "without.pcap", opensky2 / "sensors.toml")
    assert differences(ref, got) == []
    n = _plots_in_block(pk[k][1][UDP_DATA:])
    assert n >= 1 and src.stats.late_dropped == n
    assert 40.0 - 4.0 < src.stats.max_late_s < 40.0 + 4.0  # the block spans a few s
    lines = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    head = f"{tmp_path / 'late.pcap'}: {n} plot{'s' if n > 1 else ''} dropped, late by "
    assert len(lines) == 1 and lines[0].startswith(head), lines
    offset = PCAP_HEAD + sum(len(r) for r in late[:to - 1]) + UDP_DATA
    assert f"first at byte {offset} (plot " in lines[0] and "mhtrack-asterix" not in lines[0]
    # the former path (decoded to a table, then read_plots) refused it, naming a file
    # the user never made; read_plots now keeps and drops by the sources' one rule
    assert differences(_today(tmp_path / "late.pcap", opensky2 / "sensors.toml")[0],
                       got) == []
    # `mhtrack track` tracks it: one warning line, tracks equal to those without the packet
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    outs = []
    for name in ("late.pcap", "without.pcap"):
        out = tmp_path / f"{name}.csv"
        r = CliRunner().invoke(cli, ["track", str(tmp_path / name), "--sensors",
                                      str(opensky2 / "sensors.toml"), "--out", str(out)])
        assert r.exit_code == 0, r.output
        assert "tmp" not in r.output.replace(str(tmp_path), "")  # no temporary file named
        outs.append(pacsv.read_csv(out).to_pydict())
    # the same tracks; the `plot` column names each plot in its own file, where the late
    # packet's plots come before the later ones
    late_plot, without_plot = outs[0].pop("plot"), outs[1].pop("plot")
    assert outs[0] == outs[1]
    first = _decoded_before(late, to - 1)  # plots decoded before the moved packet
    assert late_plot == [p if p is None or p < first else p + n for p in without_plot]


def _decoded_before(packets: list[bytes], k: int) -> int:
    """Plots in the CAT048 packets before packet ``k``."""
    return sum(_plots_in_block(r[UDP_DATA:]) for r in packets[:k] if r[UDP_DATA] == 48)


def _plots_in_block(block: bytes) -> int:
    from mhtrack.io.asterix.decode import Decoder

    return sum(len(rows) for _, _, rows in Decoder().blocks(block, 0, Problems()))


def _shifted_csv(src: Path, out: Path, keep: object, shift: object) -> Path:
    """``src`` with the rows ``keep(t)`` kept and ``shift(t)`` added to their times."""
    lines = src.read_text().splitlines(keepends=True)
    rows = []
    for line in lines[1:]:
        t, rest = line.split(",", 1)
        if keep(float(t)):  # type: ignore[operator]
            rows.append(f"{float(t) + shift(float(t))!r},{rest}")  # type: ignore[operator]
    out.write_text(lines[0] + "".join(rows))
    return out


@pytest.mark.parametrize("suffix", [".pcap", ".ast"])
def test_midnight(opensky2: Path, recs: dict[str, Path], tmp_path: Path,
                  suffix: str) -> None:
    """The two minutes moved to 23:59:00 → 00:00:50 UTC: the same frames, times + 86 340 s
    (monotonic, past 86 400 s)."""
    sensors = read_sensors(opensky2 / "sensors.toml")
    late = _shifted_csv(opensky2 / "plots.csv", tmp_path / "m.csv", lambda t: True,
                        lambda t: 86340.0)
    export(late, sensors, tmp_path / f"m{suffix}")
    got, _ = _frames(tmp_path / f"m{suffix}", opensky2 / "sensors.toml")
    ref, _ = _frames(recs[suffix], opensky2 / "sensors.toml")
    assert differences(ref, got, shift=86340.0, shift_from=0.0) == []
    times = np.array([s.time for s in got])
    assert np.all(np.diff(times) >= 0) and times[0] < 86400.0 < times[-1]


@pytest.mark.parametrize("suffix", [".pcap", ".ast"])
def test_13_hour_gap(opensky2: Path, tmp_path: Path, suffix: str) -> None:
    """Plots before 50 s, then (after 5 quiet seconds, longer than any frame) the rest 13 h
    later: the same frames as without the gap, later times + 46 800 s."""
    sensors = read_sensors(opensky2 / "sensors.toml")
    src = opensky2 / "plots.csv"
    quiet = _shifted_csv(src, tmp_path / "q.csv", lambda t: not 50.0 <= t < 55.0,
                         lambda t: 0.0)
    export(quiet, sensors, tmp_path / f"q{suffix}")
    parts = []
    for name, keep, shift in (("a", lambda t: t < 50.0, 0.0),
                              ("b", lambda t: t >= 55.0, 46800.0)):
        part = _shifted_csv(src, tmp_path / f"{name}.csv", keep, lambda t, s=shift: s)
        export(part, sensors, tmp_path / f"{name}{suffix}")
        parts.append((tmp_path / f"{name}{suffix}").read_bytes())
    head = PCAP_HEAD if suffix == ".pcap" else 0
    (tmp_path / f"gap{suffix}").write_bytes(parts[0] + parts[1][head:])
    got, _ = _frames(tmp_path / f"gap{suffix}", opensky2 / "sensors.toml")
    ref, _ = _frames(tmp_path / f"q{suffix}", opensky2 / "sensors.toml")
    assert differences(ref, got, shift=46800.0, shift_from=55.0) == []
    times = np.array([s.time for s in got])
    assert np.all(np.diff(times) >= 0) and times[-1] > 46800.0


def test_radar_missing_from_sensors_file(opensky2: Path, recs: dict[str, Path],
                                         tmp_path: Path,
                                         caplog: pytest.LogCaptureFixture) -> None:
    """A radar neither in the sensors file nor sending its site (I034/120) is skipped,
    one warning line; the other radars' frames are those of the full sensors file."""
    sensors = read_sensors(opensky2 / "sensors.toml")
    write_sensors(replace(sensors, sensors=sensors.sensors[:2]), tmp_path / "two.toml")
    with caplog.at_level(logging.WARNING, logger="mhtrack"):
        got, src = _frames(recs[".pcap"], tmp_path / "two.toml")
    ref, _ = _frames(recs[".pcap"], opensky2 / "sensors.toml")
    mine = [f for f in ref if f.sensor[0] != 3]
    assert len(got) == len(mine) and all(
        np.array_equal(a.z, b.z) and np.array_equal(a.t, b.t) for a, b in
        zip(got, mine, strict=True))
    n3 = sum(len(f.sensor) for f in ref if f.sensor[0] == 3)
    assert n3 > 0 and src.stats.skipped["no_site"] == n3
    lines = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(lines) == 1 and lines[0].startswith(f"{recs['.pcap']}: 1 radar(s) without a "
                                                   f"known site skipped, {n3} plots")
    assert "3 (SAC 0, SIC 3)" in lines[0]


def test_damaged_recording_warns_and_goes_on(recs: dict[str, Path], opensky2: Path,
                                             tmp_path: Path,
                                             caplog: pytest.LogCaptureFixture) -> None:
    data = recs[".pcap"].read_bytes()
    (tmp_path / "cut.pcap").write_bytes(data[:-30])  # the last packet cut short
    with caplog.at_level(logging.WARNING, logger="mhtrack"):
        got, src = _frames(tmp_path / "cut.pcap", opensky2 / "sensors.toml")
    ref, _ = _frames(recs[".pcap"], opensky2 / "sensors.toml")
    assert len(got) > 300 and src.stats.plots_out <= sum(len(f) for f in ref)
    start = len(data) - 30 - _last(data)  # the cut packet's record
    assert src.stats.skipped == {"resync": 1, "skipped_octets": len(data) - 30 - start}
    lines = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert lines == [f"{tmp_path / 'cut.pcap'}: 1 damaged framing record(s) or packet(s): "
                     f"reading went on at the next valid one (first at byte {start})",
                     f"{tmp_path / 'cut.pcap'}: {_last(data)} octet(s) of damaged framing "
                     f"skipped (first at byte {start})"]


def _last(data: bytes) -> int:
    """Bytes of the last packet record that remain in front of the cut."""
    return len(_packets(data)[-1][1]) - 30


def test_not_a_recording_without_sensors(recs: dict[str, Path]) -> None:
    with pytest.raises(InputError, match=r"no plot with a measured position of a radar "
                       r"with a known site \(radars 1 \(SAC 0, SIC 1\), "):
        open_source(recs[".ast"]).survey()  # simulated: no I034/120, no sensors file


@pytest.mark.parametrize("lag", [0.1, 1.0, 3.0, 20.0])
def test_a_second_lan_behind_changes_nothing(opensky2: Path, recs: dict[str, Path],
                                             lag: float) -> None:
    """Every datagram again on a second LAN ``lag`` s of capture time behind, merged in
    time order: the frames of the one LAN, one duplicate per datagram (before: a second
    LAN 1 s behind — past the 0.5 s duplicate window, within the 2 s re-order window —
    doubled every plot, and one 3 s behind the plots at the last time released)."""
    data = recs[".pcap"].read_bytes()
    grams = [(bytes(p), when) for _, when, p in units(data, "pcap", "x", {34, 48},
                                                       Problems())]
    two = sorted(grams + [(p, t + lag) for p, t in grams], key=lambda g: g[1])
    sensors = read_sensors(opensky2 / "sensors.toml")
    ref = list(DatagramSource(grams, sensors=sensors))
    src = DatagramSource(two, sensors=sensors)
    assert differences(ref, list(src)) == []
    assert src.problems.counts.get("duplicate", 0) == len(grams)
    assert src.stats.late_dropped == 0
