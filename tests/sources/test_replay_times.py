"""``replay --loops``'s times (:mod:`mhtrack.sources.replay`): a raw recording starting
with untimed blocks (a CAT001-only block) takes its first known time, on the wire the
CAT001 plot's I001/141 moved by the pass length worked by hand; a recording without any
time refused; the time items found before the clock starts; blocks left unmoved counted;
the pass length of a recording not in time order worked by hand."""

from __future__ import annotations

import math
import socket
import struct
from pathlib import Path

import pytest
from udp_drain import drain

import mhtrack.sources.replay as replay_mod
from mhtrack.errors import InputError
from mhtrack.io.asterix import read_recording, wrap
from mhtrack.io.asterix.retime import time_layout
from mhtrack.io.asterix.timeaxis import DAY_S
from mhtrack.sources.replay import pass_seconds, recording_datagrams, replay, schedule

pytest.importorskip("asterix.generated", reason="libasterix not installed")


def _plot001(tod: int) -> bytes:
    """One CAT001 data block of one plot (layout of tests/io/asterix/test_retime.py)
    at ``tod`` s, its I001/141 the time truncated to 16 bits (1/128 s)."""
    plot = bytes([0b11111010, 7, 9, 0b00110001, 0b10000000]) + struct.pack(
        "!HHHHH", 12800, 16384, 0o7700, 1400, tod * 128 % 65536)
    return bytes([1]) + (3 + len(plot)).to_bytes(2, "big") + plot


@pytest.fixture(scope="module")
def blocks(opensky2: Path, tmp_path_factory: pytest.TempPathFactory) -> list[bytes]:
    """The first 40 data blocks of the exported opensky-radars recording (raw)."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    out = tmp_path_factory.mktemp("replay_times") / "r.ast"
    r = CliRunner().invoke(cli, ["export", str(opensky2 / "plots.csv"), "--sensors",
                                 str(opensky2 / "sensors.toml"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    return [p for p, _ in recording_datagrams(out)[:40]]


def _send(path: Path, loops: int) -> tuple[replay_mod.ReplayStats, list[bytes]]:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as rx:
        rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        rx.bind(("127.0.0.1", 0))
        stats = replay(path, f"udp://127.0.0.1:{rx.getsockname()[1]}", speed=math.inf,
                       loops=loops)
        return stats, drain(rx)


def test_leading_untimed_blocks_take_the_first_time(blocks: list[bytes],
                                                    tmp_path: Path) -> None:
    rest = tmp_path / "rest.ast"
    rest.write_bytes(b"".join(blocks))
    times = [t for _, t in recording_datagrams(rest)]
    t1 = times[0]
    tod = round(t1) % int(DAY_S)
    path = tmp_path / "lead.ast"
    path.write_bytes(_plot001(tod) + b"".join(blocks))
    got = recording_datagrams(path)
    assert [t for _, t in got] == [t1, *times]  # not 0.0 for the CAT001 block
    # S by hand: the span of the same times plus one mean spacing of the 41, rounded up
    span = max(times) - min(times)
    every = math.ceil(span + span / len(times))
    assert every < 600
    stats, wire = _send(path, 2)
    assert stats.datagrams == 82 and len(wire) == 82
    assert wire[0] == _plot001(tod)
    assert wire[41] == _plot001(tod + every)  # I001/141 moved by S, no more


def test_a_recording_without_times_is_not_looped(tmp_path: Path) -> None:
    path = tmp_path / "untimed.ast"
    path.write_bytes(_plot001(100) * 3)
    with pytest.raises(InputError, match=r"untimed\.ast: no datagram has a time of day"):
        _send(path, 2)
    stats, wire = _send(path, 1)  # once: nothing to move
    assert stats.datagrams == 3 and wire == [_plot001(100)] * 3


def test_time_items_found_before_the_clock_starts(blocks: list[bytes], tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "r.ast"
    path.write_bytes(b"".join(blocks[:10]))
    started, late, calls = [False], [], []

    def layout(payload: bytes) -> tuple[tuple[tuple[int, int, int], ...], int]:
        calls.append(payload)
        late.append(started[0])
        return time_layout(payload)

    def clock() -> float:
        started[0] = True
        return 0.0

    monkeypatch.setattr(replay_mod, "time_layout", layout)
    stats = replay(path, "udp://127.0.0.1:9", speed=math.inf, loops=3, clock=clock)
    assert stats.datagrams == 30
    assert calls == blocks[:10] and not any(late)


def test_blocks_left_unmoved_are_counted(blocks: list[bytes], tmp_path: Path) -> None:
    good = blocks[0]
    assert good[0] in (34, 48) and time_layout(good)[1] == 0 and time_layout(good)[0]
    # the same block one octet longer: its records no longer fill it
    bad = good[:1] + (len(good) + 1).to_bytes(2, "big") + good[3:] + b"\xff"
    assert time_layout(bad) == ((), 1)
    # in a pcap each datagram is sent as captured, the bad block with it
    path = tmp_path / "bad.pcap"
    path.write_bytes(wrap.pcap(wrap.udp_frames([good, bad, good], 258), [0.0, 1.0, 2.0]))
    stats, wire = _send(path, 3)
    assert stats.datagrams == 9 and stats.unmoved == 2  # passes 2 and 3
    assert wire[4] == bad and wire[7] == bad and wire[3] != good
    # a raw stream is read as convert reads it: the block its records do not fill is
    # damage, skipped (and so never sent)
    path = tmp_path / "bad.ast"
    path.write_bytes(good + bad + good)
    assert [p for p, _ in recording_datagrams(path)] == [good, good]
    rec = read_recording(path)
    assert rec.problems.counts == {"resync": 1, "skipped_octets": len(bad), "duplicate": 1}
    assert rec.problems.first["resync"] == len(good)


def test_pass_length_of_a_recording_out_of_time_order() -> None:
    # span 20 - 10 = 10 s (not 12 - 10), mean spacing 5 s: passes 15 s apart
    assert pass_seconds([10.0, 20.0, 12.0]) == 15
    assert list(schedule([10.0, 20.0, 12.0], 1.0, 2)) == [
        (0, 0.0), (1, 10.0), (2, 2.0), (0, 15.0), (1, 25.0), (2, 17.0)]
    # a time before the first: the next pass still starts after every due time
    due = [d for _, d in schedule([10.0, 4.0, 12.0], 1.0, 2)]
    assert due[3] > max(due[:3])


def test_the_summary_line_counts_them(blocks: list[bytes], tmp_path: Path) -> None:
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    good = blocks[0]
    bad = good[:1] + (len(good) + 1).to_bytes(2, "big") + good[3:] + b"\xff"
    path = tmp_path / "bad.pcap"
    path.write_bytes(wrap.pcap(wrap.udp_frames([good, bad], 258), [0.0, 1.0]))
    r = CliRunner().invoke(cli, ["replay", str(path), "--to", "udp://127.0.0.1:9",
                                 "--loops", "3", "--speed", "max"])
    assert r.exit_code == 0, r.output
    assert "sent 6 datagrams" in r.output
    assert "2 blocks sent with their old times" in r.output
    (tmp_path / "none.ast").write_bytes(_plot001(5))
    r = CliRunner().invoke(cli, ["replay", str(tmp_path / "none.ast"), "--to",
                                 "udp://127.0.0.1:9", "--loops", "2"])
    assert r.exit_code != 0 and "no datagram has a time of day" in r.output
