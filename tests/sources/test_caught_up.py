"""A live feed's chunks (:data:`~mhtrack.sources.base.CAUGHT_UP`): the datagrams that
queued up decoded as one chunk give the frames of the former live path (each data block
passed on alone, ``chunk=1``), wherever the markers fall; and ``decoded`` — read by the
health's latency bookkeeping when a datagram is taken — counts the plots of the
datagrams before it (counted here datagram by datagram, each decoded on its own)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from mhtrack.io.asterix import export
from mhtrack.io.sensors import read_sensors
from mhtrack.sources.base import CAUGHT_UP
from mhtrack.sources.datagrams import DatagramSource
from mhtrack.sources.replay import recording_datagrams

from .conftest import differences


@pytest.fixture(scope="module")
def feed(opensky2: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[list, Path]:
    path = tmp_path_factory.mktemp("caught") / "rec.pcap"
    export(opensky2 / "plots.csv", read_sensors(opensky2 / "sensors.toml"), path)
    return [d for d, _ in recording_datagrams(path)], opensky2 / "sensors.toml"


@pytest.mark.parametrize("seed", [0, 1])
def test_chunks_give_the_frames_of_one_datagram_at_a_time(feed, seed: int) -> None:
    datagrams, sensors_file = feed
    sensors = read_sensors(sensors_file)
    one = list(DatagramSource(datagrams, sensors=sensors, chunk=1, reorder_window_s=0.2))
    rng = np.random.default_rng(seed)
    marked: list = []
    for d in datagrams:  # runs of 1 to 60 datagrams between markers
        marked.append(d)
        if rng.random() < 0.1:
            marked.append(CAUGHT_UP)
    src = DatagramSource(marked, sensors=sensors, reorder_window_s=0.2)
    chunked = list(src)
    assert len(one) > 20 and not differences(one, chunked)
    assert src.stats.plots_out == sum(len(s.rows) for s in one)


def test_decoded_counts_the_plots_before_each_datagram(feed) -> None:
    datagrams, sensors_file = feed
    sensors = read_sensors(sensors_file)
    seen: list[int] = []

    def taken():
        for d in datagrams:
            seen.append(src.decoded)  # as the live run notes a receive time
            yield d
            yield CAUGHT_UP

    src = DatagramSource(taken(), sensors=sensors, reorder_window_s=0.2)
    list(src)
    alone = [0]
    for d in datagrams:  # each datagram's plots, decoded on its own
        one = DatagramSource([d], sensors=sensors)
        list(one)
        alone.append(alone[-1] + one.decoded)
    assert seen == alone[:-1] and src.decoded == alone[-1] > 0
