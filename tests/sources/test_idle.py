"""A live feed gone quiet (issue 30): the reader's ``IDLE`` (a bounded wall-clock wait
without a datagram, :mod:`mhtrack.sources.udp`) makes the datagram source close the
frames it holds — the frames a source whose input ended there gives — instead of
waiting for plots that never come; the stream then goes on. Without ``IDLE`` (a file, a
replay read to its end) nothing changes. No clock here: ``IDLE`` is put in the input."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from sim_recording import simulated_recording  # tests/helpers

from mhtrack.io.sensors import read_sensors
from mhtrack.sources.base import IDLE
from mhtrack.sources.datagrams import DatagramSource
from mhtrack.sources.replay import recording_datagrams


@pytest.fixture(scope="module")
def rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(tmp_path_factory.mktemp("idle"), seed=2, scans=4)


def _key(f) -> tuple:
    return f.index, f.time, f.rows.tolist(), f.z.tolist(), f.sensor.tolist()


@pytest.mark.parametrize("share", [0.3, 0.6])
def test_idle_closes_the_frames_as_an_end_would(rec: Path, share: float) -> None:
    blocks = [d for d, _ in recording_datagrams(rec / "radar.ast")]
    k = int(share * len(blocks))
    sensors = read_sensors(rec / "sensors.toml")
    ended = [_key(f) for f in DatagramSource(blocks[:k], sensors=sensors)]
    read = {"after": False}

    def feed(idle: bool) -> Iterator[object]:
        read["after"] = False
        yield from blocks[:k]
        if idle:
            yield IDLE
        read["after"] = True  # the source asks for the datagrams after the quiet
        yield from blocks[k:]

    def frames(idle: bool) -> tuple[list, list, DatagramSource]:
        src = DatagramSource(feed(idle), sensors=sensors)
        before, after = [], []
        for f in src:
            (after if read["after"] else before).append(_key(f))
        return before, after, src

    before, after, src = frames(idle=True)
    assert before == ended  # every frame held went out, as at an end of input
    assert src.idles == 1
    waiting, _, plain = frames(idle=False)
    assert len(waiting) < len(ended)  # without it, frames wait for later plots
    assert plain.idles == 0
    # the stream went on: numbered on, in time order, every plot tracked or a late drop
    assert [a[0] for a in after] == list(range(len(before), len(before) + len(after)))
    times = [f[1] for f in before + after]
    assert times == sorted(times)
    s = src.stats
    assert s.plots_out + s.late_dropped == s.plots_in == plain.stats.plots_in
    rows = np.concatenate([f[2] for f in before + after])
    assert np.array_equal(rows, np.arange(s.plots_out))
