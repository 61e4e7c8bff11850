"""``replay`` (:mod:`mhtrack.sources.replay`): the datagrams and times read from a pcap
and from a raw recording of the same blocks, the schedule worked by hand, and a replay on
a fake clock received in order on loopback."""

from __future__ import annotations

import math
import socket
from pathlib import Path

import numpy as np
import pytest
from udp_drain import drain

from mhtrack.io.asterix.decode import Decoder
from mhtrack.io.asterix.framings import recognise, units
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import TimeAxis
from mhtrack.sources.replay import pass_seconds, recording_datagrams, replay, schedule

pytest.importorskip("asterix.generated", reason="libasterix not installed")


@pytest.fixture(scope="module")
def recordings(opensky2: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The same plots exported as a pcap and as raw blocks."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    out = tmp_path_factory.mktemp("replay")
    for name in ("r.pcap", "r.ast"):
        r = CliRunner().invoke(cli, ["export", str(opensky2 / "plots.csv"), "--sensors",
                                     str(opensky2 / "sensors.toml"), "--out",
                                     str(out / name)])
        assert r.exit_code == 0, r.output
    return out


def test_pcap_and_raw_give_the_same_datagrams(recordings: Path) -> None:
    pcap = recording_datagrams(recordings / "r.pcap")
    data = (recordings / "r.pcap").read_bytes()
    cats = Decoder().categories
    ref = [(at, payload, when) for at, when, payload in units(
        data, recognise(data, "r", cats), "r", cats, Problems())]
    assert [p for p, _ in pcap] == [bytes(p) for _, p, _ in ref]
    assert [t for _, t in pcap] == [t for _, _, t in ref]
    raw = recording_datagrams(recordings / "r.ast")
    # export writes one data block per pcap datagram: the raw file's blocks are the same
    assert [p for p, _ in raw] == [p for p, _ in pcap]
    assert b"".join(p for p, _ in raw) == (recordings / "r.ast").read_bytes()
    # a raw block's time is its first record's time of day (1/128 s), the pcap's the
    # message time (µs): equal within the time of day's LSB
    diff = np.array([a for _, a in raw]) - np.array([b for _, b in pcap])
    assert np.abs(diff).max() <= 1 / 128


def test_schedule_by_hand() -> None:
    got = list(schedule([10.0, 11.0, 13.0], 2.0, 2))
    # span 3 s, mean spacing 1.5 s: the second pass starts at 4.5 s, halved by speed 2
    assert got == [(0, 0.0), (1, 0.5), (2, 1.5), (0, 2.25), (1, 2.75), (2, 3.75)]
    assert [d for _, d in schedule([5.0, 9.0], math.inf, 1)] == [0.0, 0.0]
    endless = schedule([1.0], 1.0, None)
    assert [next(endless) for _ in range(3)] == [(0, 0.0)] * 3
    # passes every 5 s (span 3 + spacing 1.5 = 4.5, rounded up): at speed 2, 2.5 s apart
    assert pass_seconds([10.0, 11.0, 13.0]) == 5
    assert list(schedule([10.0, 11.0, 13.0], 2.0, 2, every=5)) == [
        (0, 0.0), (1, 0.5), (2, 1.5), (0, 2.5), (1, 3.0), (2, 4.0)]
    assert pass_seconds([7.0]) == 1


def _times(payloads: list[bytes]) -> list[float]:
    """Plot and mark times, in order, on one time axis."""
    decoder, axis, out = Decoder(duplicates=False), TimeAxis(), []
    for p in payloads:
        for _, _, found in decoder.blocks(p, 0, Problems()):
            out.extend(axis.times_list([r[0] for r in found]))
    return out


def test_a_loop_moves_the_times_on(recordings: Path) -> None:
    """Three passes of 150 datagrams at ``max``: pass ``n`` is the recording's datagrams
    with every time ``n · S`` later (decoded on one axis: later passes are not late)."""
    items = recording_datagrams(recordings / "r.pcap")[:150]
    path = recordings / "loop.ast"
    path.write_bytes(b"".join(p for p, _ in items))
    items = recording_datagrams(path)
    every = pass_seconds([t for _, t in items])
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as rx:
        rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        rx.bind(("127.0.0.1", 0))
        stats = replay(path, f"udp://127.0.0.1:{rx.getsockname()[1]}", speed=math.inf,
                       loops=3)
        got = drain(rx)
    assert (stats.datagrams, stats.passes) == (450, 3) and len(got) == 450
    assert got[:150] == [p for p, _ in items]
    t = np.array(_times(got)).reshape(3, -1)
    assert np.array_equal(t[1] - t[0], np.full(t.shape[1], float(every)))
    assert np.array_equal(t[2] - t[0], np.full(t.shape[1], 2.0 * every))
    assert np.all(np.diff(t.ravel()) >= -1.0)  # in time order across the passes
    # the same times again without moving them
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as rx:
        rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        rx.bind(("127.0.0.1", 0))
        replay(path, f"udp://127.0.0.1:{rx.getsockname()[1]}", speed=math.inf, loops=2,
               move_times=False)
        assert drain(rx) == [p for p, _ in items] * 2


def test_replay_on_a_fake_clock(recordings: Path) -> None:
    items = recording_datagrams(recordings / "r.pcap")[:200]
    path = recordings / "short.ast"
    path.write_bytes(b"".join(p for p, _ in items))
    items = recording_datagrams(path)
    now = [0.0]
    slept: list[float] = []

    def sleep(s: float) -> None:
        slept.append(s)
        now[0] += s

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as rx:
        rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        rx.bind(("127.0.0.1", 0))
        stats = replay(path, f"udp://127.0.0.1:{rx.getsockname()[1]}", speed=10.0,
                       clock=lambda: now[0], sleep=sleep)
        got = drain(rx)
    assert got == [p for p, _ in items], "loopback lost or re-ordered datagrams"
    assert (stats.datagrams, stats.passes) == (200, 1)
    assert now[0] == pytest.approx((items[-1][1] - items[0][1]) / 10)
    assert all(s > 0 for s in slept)


def test_bad_speed() -> None:
    with pytest.raises(ValueError, match="speed must be above 0"):
        replay("x", "udp://127.0.0.1:9", speed=0.0)


def test_a_stop_ends_a_long_wait(recordings: Path) -> None:
    import threading

    stop = threading.Event()
    waits: list[float] = []

    def clock() -> float:
        return 0.0

    def sleep(s: float) -> None:  # the first wait sets the stop: nothing more is sent
        waits.append(s)
        stop.set()

    stats = replay(recordings / "r.pcap", "udp://127.0.0.1:9", speed=1e-6, stop=stop,
                   clock=clock, sleep=sleep)
    assert stats.datagrams == 1 and len(waits) == 1 and waits[0] > 1e5
