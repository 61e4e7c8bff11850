"""``live --sector-frames`` (:mod:`mhtrack.sources.marks`): the frames cut and closed at
the radars' own CAT034 sector crossings give the same online rows as ``track
--sector-frames --output online`` on the same recording, for ``release="time"``; the
option changes the frames (the test can tell)."""

from __future__ import annotations

import json
import os
import threading
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from click.testing import CliRunner
from sim_recording import simulated_recording  # tests/helpers

from mhtrack.cli.main import cli
from mhtrack.io import read_tracks
from mhtrack.io.sensors import read_sensors
from mhtrack.pipeline import TrackOptions
from mhtrack.pipeline.live import Live, LiveOptions
from mhtrack.sinks.base import Sink

OPTIONS = TrackOptions(output="online", new_target_density=1e-10)


@pytest.fixture(scope="module")
def rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(tmp_path_factory.mktemp("livesec"), seed=2, scans=5)


def _live(rec: Path, sectors: bool) -> tuple[list[dict], list[tuple[int, ...]]]:
    """``live --stdin raw`` on the recording: its JSON rows and each frame's file rows."""
    import io

    out = io.StringIO()
    frames: list[tuple[int, ...]] = []

    class Frames(Sink):
        def write(self, o) -> None:
            frames.append(tuple(live.source.file_rows(o.frame.rows).tolist()))

    r, w = os.pipe()
    data = (rec / "radar.ast").read_bytes()
    writer = threading.Thread(target=lambda: (os.write(w, data), os.close(w)))
    with os.fdopen(r, "rb", buffering=0) as rf:
        live = Live(read_sensors(rec / "sensors.toml"), OPTIONS,
                    LiveOptions(preload=False, stdin="raw", day_from="stream", json=True,
                                sectors=sectors), stdin=rf, stdout=out)
        live.sinks.append(Frames())
        writer.start()
        live.run()
        writer.join()
    assert live.source.stats.plots_in == live.source.stats.plots_out + \
        live.source.stats.late_dropped  # marks are no plots: none counted as one
    return [json.loads(x) for x in out.getvalue().splitlines()], frames


def test_live_sector_frames_equal_track_online(rec: Path) -> None:
    rows, frames = _live(rec, sectors=True)
    out = rec / "online.csv"
    r = CliRunner().invoke(cli, ["track", str(rec / "radar.ast"), "--sensors",
                                 str(rec / "sensors.toml"), "--sector-frames", "--output",
                                 "online", "--birth-density", "1e-10", "--out", str(out),
                                 "-q"])
    assert r.exit_code == 0, r.output
    t = read_tracks(out)
    assert len(rows) == len(t) > 0
    assert [x["frame"] for x in rows] == t.scan.tolist()
    assert [x["track_id"] for x in rows] == t.track_id.tolist()
    assert np.allclose([x["x"] for x in rows], t.x, atol=5e-4, rtol=0)
    assert np.allclose([x["time"] for x in rows], t.time, atol=1e-6, rtol=0)
    _, plain = _live(rec, sectors=False)
    assert frames != plain  # the option is what made these frames
    assert sorted(p for f in frames for p in f) == sorted(p for f in plain for p in f)


def test_sector_frames_do_not_depend_on_the_chunks(rec: Path) -> None:
    from mhtrack.sources.datagrams import DatagramSource
    from mhtrack.sources.replay import recording_datagrams

    grams = [d for d, _ in recording_datagrams(rec / "radar.ast")]
    sensors = read_sensors(rec / "sensors.toml")

    def frames(chunk: int) -> list[tuple]:
        return [(f.index, f.time, f.rows.tolist(), f.z.tolist()) for f in
                DatagramSource(grams, sensors=sensors, sectors=True, chunk=chunk)]

    one = frames(1)
    assert len(one) > 10 and frames(7) == one and frames(1024) == one


def test_sector_frames_are_never_fused(rec: Path) -> None:
    """A sector frame is one radar's plots with their own times: ``live`` (as ``track``
    on a recording) refuses ``--fusion adaptive-kmeans`` — it fuses plots of several
    radars at one scan time — in one line, before any datagram is read; with the
    default (``none``) each frame goes to the tracker as it was cut, its closing crossing
    (``Scan.closing``) with it. So no fused frame ever holds sector frames whose
    crossings it could lose (``docs/live.md``, *Health and latency*)."""
    import dataclasses
    import io

    from mhtrack.pipeline.run import fused
    from mhtrack.sources.datagrams import DatagramSource
    from mhtrack.sources.replay import recording_datagrams

    with pytest.raises(ValueError, match="one sensor per frame: use fusion 'none'"):
        Live(read_sensors(rec / "sensors.toml"),
             dataclasses.replace(OPTIONS, fusion="adaptive-kmeans"),
             LiveOptions(preload=False, stdin="raw", day_from="stream", sectors=True),
             stdin=io.BytesIO(b""))
    grams = [d for d, _ in recording_datagrams(rec / "radar.ast")]
    frames = list(DatagramSource(grams, sensors=read_sensors(rec / "sensors.toml"),
                                 sectors=True))
    out = list(fused(frames, "none"))
    assert [f.closing for f in out] == [f.closing for f in frames]
    assert sum(f.closing is not None for f in out) > len(out) // 2  # most by a crossing


def test_track_refuses_to_fuse_sector_frames(rec: Path) -> None:
    r = CliRunner().invoke(cli, ["track", str(rec / "radar.ast"), "--sensors",
                                 str(rec / "sensors.toml"), "--sector-frames", "--fusion",
                                 "adaptive-kmeans", "--out", str(rec / "fused.csv"), "-q"])
    assert r.exit_code != 0 and not (rec / "fused.csv").exists()
    assert "one sensor per frame: use fusion 'none'" in r.output.strip().splitlines()[-1]
