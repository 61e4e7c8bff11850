"""The live assembly (:mod:`mhtrack.pipeline.live`): what it refuses, its status line
worked by hand, and a run over stdin giving the online rows of the pipeline on the
recording file."""

from __future__ import annotations

import dataclasses
import io
import json
import os
import threading
from pathlib import Path
from types import SimpleNamespace
from typing import BinaryIO

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from sim_recording import simulated_recording  # tests/helpers

from mhtrack.io.sensors import read_sensors
from mhtrack.pipeline import Pipeline, TrackOptions
from mhtrack.pipeline.health import Health
from mhtrack.pipeline.live import Live, LiveOptions
from mhtrack.sinks import TrackCollector
from mhtrack.sources.replay import recording_datagrams

OPTIONS = TrackOptions(output="online", new_target_density=1e-10)


@pytest.fixture(scope="module")
def rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(tmp_path_factory.mktemp("live"), seed=2, scans=5)


def _pipe(data: bytes) -> tuple[BinaryIO, threading.Thread]:
    r, w = os.pipe()
    return os.fdopen(r, "rb", buffering=0), threading.Thread(
        target=lambda: (os.write(w, data), os.close(w)))


def test_refusals(rec: Path) -> None:
    sensors = read_sensors(rec / "sensors.toml")
    no_period = dataclasses.replace(sensors, sensors=tuple(
        dataclasses.replace(s, period=None) if s.id == 2 else s for s in sensors.sensors))
    rf, writer = _pipe(b"")  # no CAT034 mark to take a period from
    writer.start()
    with rf, pytest.raises(ValueError, match=r"no rotation period for radar\(s\) 2"):
        Live(no_period, OPTIONS, LiveOptions(preload=False, stdin="raw"), stdin=rf)
    writer.join()
    with pytest.raises(ValueError, match="one of them"):
        Live(sensors, OPTIONS, LiveOptions(preload=False))


def test_periods_and_density_from_the_first_rotations(rec: Path, tmp_path: Path) -> None:
    """Without periods in the sensors file nor a density, live takes them from its
    first rotations: the periods are the file's (the export sends I034/041), the density
    is the one track chooses for a recording of exactly the datagrams held, and the rows
    are those of the pipeline given both — nothing held is lost."""
    sensors = read_sensors(rec / "sensors.toml")
    bare = dataclasses.replace(sensors, sensors=tuple(
        dataclasses.replace(s, period=None) for s in sensors.sensors))
    data = (rec / "radar.ast").read_bytes()
    rf, writer = _pipe(data)
    out = io.StringIO()
    lines: list[str] = []
    with rf:
        writer.start()
        live = Live(bare, TrackOptions(output="online"),
                    LiveOptions(preload=False, stdin="raw", day_from="stream", json=True), stdin=rf,
                    stdout=out, emit=lines.append)
        live.run()
        writer.join()
    warm = live.warmup
    assert warm is not None and len(warm.datagrams) < len(recording_datagrams(
        rec / "radar.ast"))  # the first rotations only
    slowest = max(s.period for s in sensors.sensors)
    assert 2 * slowest <= warm.span_s < 2 * slowest + 1.0
    assert {s.id: s.period for s in live.source.sensors.sensors} == pytest.approx(
        {s.id: s.period for s in sensors.sensors}, rel=1e-3)
    first = tmp_path / "first.ast"
    first.write_bytes(b"".join(d for d, _ in warm.datagrams))
    surveyed = Pipeline.open(str(first), TrackOptions(output="online"),
                             sensors_file=str(rec / "sensors.toml"))
    density = live.pipeline.config.new_target_density
    assert density == surveyed.config.new_target_density
    assert any("new-target density" in x for x in lines)
    ref = TrackCollector("online")
    Pipeline.open(str(rec / "radar.ast"), dataclasses.replace(
        OPTIONS, new_target_density=density), sensors_file=str(rec / "sensors.toml")
    ).run([ref])
    rows = [json.loads(x) for x in out.getvalue().splitlines()]
    assert [r["track_id"] for r in rows] == ref.tracks().track_id.tolist()
    assert np.allclose([r["x"] for r in rows], ref.tracks().x, atol=5e-4, rtol=0)


def test_status_line_by_hand() -> None:
    counts = {"datagrams": 10, "queue_drops": 1, "plots": 40, "duplicates": 3,
              "late_drops": 2, "kernel_drops": None}
    clock = iter([100.0, 104.0, 104.2, 104.5])  # line, frame out, frame out, line
    st = Health(lambda: counts, lambda: 3, lambda out: np.array([0]), {1: 4.0, 2: 12.0},
                lambda: next(clock))
    assert st.line() == ("live: 10 datagrams, 40 plots, 3 duplicates, 2 late drops, "
                         "1 queue drops, kernel drops n/a, 0 frames, 0 tracks, "
                         "0 radars silent")
    counts.update(datagrams=30, plots=140, kernel_drops=7)
    st.arrivals.add(0, 103.9)  # plot 0 came at 103.9 s: latencies 0.1 s and 0.3 s
    frame = SimpleNamespace(time=50.0, sensor=np.array([2]), rows=np.array([0]))
    st.write(SimpleNamespace(frame=frame))
    st.write(SimpleNamespace(frame=SimpleNamespace(time=63.0, sensor=np.array([2]),
                                                    rows=np.array([0]))))
    # radar 1 never sent a frame in 13 s > 3 x 4 s: silent; radar 2 sent one at 63 s
    # 20 datagrams and 100 plots in 4.5 s; p50 of (0.1, 0.3) 0.2 s, p99 0.1 + 0.99 x 0.2
    assert st.line() == ("live: 4.4 datagrams/s, 22.2 plots/s, 30 datagrams, 140 plots, "
                         "3 duplicates, 2 late drops, 1 queue drops, 7 kernel drops, "
                         "2 frames, 3 tracks, "
                         "1 radars silent (1), latency p50 200 ms p99 298 ms")


def test_stdin_run_equals_the_pipeline_on_the_file(rec: Path) -> None:
    sensors = read_sensors(rec / "sensors.toml")
    ref = TrackCollector("online")
    Pipeline.open(str(rec / "radar.ast"), OPTIONS,
                  sensors_file=str(rec / "sensors.toml")).run([ref])
    t = ref.tracks()
    r, w = os.pipe()
    data = (rec / "radar.ast").read_bytes()
    writer = threading.Thread(target=lambda: (os.write(w, data), os.close(w)))
    out = io.StringIO()
    with os.fdopen(r, "rb", buffering=0) as rf:
        live = Live(sensors, OPTIONS, LiveOptions(preload=False,
                                                  stdin="raw", day_from="stream", json=True),
                    stdin=rf, stdout=out)
        writer.start()
        result = live.run()
        writer.join()
    rows = [json.loads(x) for x in out.getvalue().splitlines()]
    assert len(rows) == len(t) > 0
    assert [x["track_id"] for x in rows] == t.track_id.tolist()
    assert np.allclose([x["x"] for x in rows], t.x, atol=5e-4, rtol=0)
    assert np.allclose([x["time"] for x in rows], t.time, atol=1e-6, rtol=0)  # to 1 µs
    # raw stdin: one datagram per data block of the file
    assert result.reader.datagrams == len(recording_datagrams(rec / "radar.ast"))
    assert live.source.stats.plots_in == live.source.stats.plots_out + \
        live.source.stats.late_dropped


def test_stopped_before_any_datagram(rec: Path, tmp_path: Path) -> None:
    stop = threading.Event()
    live = Live(read_sensors(rec / "sensors.toml"), OPTIONS,
                LiveOptions(preload=False,
                            listen=("udp://127.0.0.1:0",), out_file=tmp_path / "e.ast"),
                stop=stop)
    stop.set()
    result = live.run()
    assert (result.reader.datagrams, len(result.run.stats), result.sent_rows) == (0, 0, 0)
    assert (tmp_path / "e.ast").read_bytes() == b""  # an empty recording, written



@pytest.mark.parametrize("preload", [None, True, False])
def test_live_preloads_unless_told_not_to(rec: Path, preload: bool | None,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """``LiveOptions()`` loads the one-time code at start; ``preload=False`` does not
    (:func:`mhtrack.pipeline.preload.preload` replaced by a counter)."""
    import mhtrack.pipeline.preload as preload_mod

    calls: list[int] = []
    monkeypatch.setattr(preload_mod, "preload", lambda: calls.append(1) or (0, False))
    stop = threading.Event()
    kw = {} if preload is None else {"preload": preload}
    live = Live(read_sensors(rec / "sensors.toml"), OPTIONS,
                LiveOptions(listen=("udp://127.0.0.1:0",), **kw), stop=stop)
    stop.set()
    live.run()
    assert calls == ([] if preload is False else [1])


def test_a_quiet_feed_closes_its_frames_on_the_idle_clock(rec: Path) -> None:
    """Half the recording written, the pipe left open (the feed gone quiet): on the idle
    clock (the test's own: one second a reading, ``idle_close_s`` 5 s) live closes the
    frames it holds and sends their rows — those of a run whose input ended there —
    before any more input; the default wait is the re-order window plus the longest
    rotation; ``0`` never closes."""
    import time

    from mhtrack.pipeline.live import idle_wait

    sensors = read_sensors(rec / "sensors.toml")
    blocks = [d for d, _ in recording_datagrams(rec / "radar.ast")]
    k = len(blocks) // 2
    head = b"".join(blocks[:k])
    rf, writer = _pipe(head)
    writer.start()
    ended = io.StringIO()
    with rf:
        Live(sensors, OPTIONS, LiveOptions(preload=False,
                                           stdin="raw", day_from="stream", json=True),
             stdin=rf, stdout=ended).run()
    writer.join()
    want = ended.getvalue().splitlines()
    assert want
    ticks = iter(range(10**9))
    r, w = os.pipe()
    out = io.StringIO()
    with os.fdopen(r, "rb", buffering=0) as rf:
        live = Live(sensors, OPTIONS, LiveOptions(preload=False,
                                                  stdin="raw", day_from="stream", json=True,
                                                  idle_close_s=5.0),
                    stdin=rf, stdout=out, idle_clock=lambda: float(next(ticks)))
        runner = threading.Thread(target=live.run)
        runner.start()
        os.write(w, head)
        for _ in range(3000):  # bounded; ends when the rows are out
            if len(out.getvalue().splitlines()) >= len(want) and live.source.idles:
                break
            time.sleep(0.01)
        got = out.getvalue().splitlines()  # before any more input
        os.close(w)
        runner.join()
    assert got == want and live.source.idles >= 1
    assert idle_wait(sensors, LiveOptions(stdin="raw")) == 2.0 + max(
        s.period for s in sensors.sensors)
    assert idle_wait(sensors, LiveOptions(stdin="raw", idle_close_s=0.0)) is None


def test_release_by_radar_tracks_the_same_frames(rec: Path) -> None:
    """``release="radar"``: the frames the tracker gets are those of the default (each
    frame's plots by row, the same set; another order), their times never go back, and
    every plot is tracked."""
    from mhtrack.sinks.base import Sink

    class Frames(Sink):
        def __init__(self) -> None:
            self.got: list[tuple[float, tuple[int, ...]]] = []

        def write(self, out) -> None:
            self.got.append((float(out.frame.time),
                             tuple(sorted(live.source.file_rows(out.frame.rows).tolist()))))

    sensors = read_sensors(rec / "sensors.toml")
    data = (rec / "radar.ast").read_bytes()
    seen = {}
    for release in ("time", "radar"):
        rf, writer = _pipe(data)
        with rf:
            live = Live(sensors, OPTIONS, LiveOptions(preload=False, stdin="raw",
                                                      day_from="stream", release=release),
                        stdin=rf)
            sink = Frames()
            live.sinks.append(sink)
            writer.start()
            live.run()
            writer.join()
        seen[release] = sink.got
        assert live.source._stream.framer.release == release
    times = [t for t, _ in seen["radar"]]
    assert times == sorted(times)
    assert sorted(p for _, p in seen["radar"]) == sorted(p for _, p in seen["time"])
    assert len(seen["time"]) > 10
