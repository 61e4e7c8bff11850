"""Issue 30's soak acceptance at small scale: ``mhtrack live --checkpoint F
--checkpoint-every M`` killed by ``kill -9`` (SIGKILL: no handler, no final checkpoint) at a
seeded random frame, then ``live --checkpoint F --resume`` on the datagrams that came after
the kill goes on from the last periodic checkpoint with the same track ids for the
aircraft still present.

Two processes fed over stdin pipes (``--stdin raw``: no datagram lost in transport), bounded
by counts: the first is killed once it has written the JSON line of the chosen frame, the
second reads to the end of its input. The reference is one run never killed, on every
datagram (the library's :class:`~mhtrack.pipeline.live.Live`, the same code): the killed
run's rows are a prefix of it; after the restart each track id carried over from the
checkpoint follows the reference's track of that id (within 1 km of its nearest update
moved on at its velocity — aircraft here are kilometres apart, a swapped id would be far
off), every reference track
alive at the checkpoint and still reported at the end is reported by the restarted run
under its id, and new tracks get new ids."""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from sim_recording import simulated_recording

from mhtrack.io.sensors import read_sensors
from mhtrack.pipeline import TrackOptions
from mhtrack.pipeline.checkpoint import read_checkpoint
from mhtrack.pipeline.live import Live, LiveOptions
from mhtrack.sources.replay import recording_datagrams

CLI = [sys.executable, "-c", "from mhtrack.cli.main import main; main()"]
DENSITY = "1e-10"
#: Minutes of data time between checkpoints (6 s: several in the recording).
EVERY_MIN = "0.1"


def _env() -> dict[str, str]:
    src = str(Path(__file__).resolve().parents[2] / "src")
    return {**os.environ, "PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}


@pytest.fixture(scope="module")
def rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(tmp_path_factory.mktemp("kill"), seed=1, scans=8)


def _reference(rec: Path, blocks: list[bytes]) -> list[dict]:
    out = io.StringIO()
    r, w = os.pipe()
    with os.fdopen(r, "rb", buffering=0) as rf:
        live = Live(read_sensors(rec / "sensors.toml"),
                    TrackOptions(output="online", new_target_density=float(DENSITY)),
                    LiveOptions(stdin="raw", day_from="stream", json=True),
                    stdin=rf, stdout=out)
        feeder = threading.Thread(target=lambda: (os.write(w, b"".join(blocks)),
                                                  os.close(w)))
        feeder.start()
        live.run()
        feeder.join()
    return [json.loads(x) for x in out.getvalue().splitlines()]


def _live(rec: Path, ck: Path, *extra: str) -> subprocess.Popen:
    return subprocess.Popen(
        [*CLI, "live", "--stdin", "raw", "--sensors", str(rec / "sensors.toml"),
         "--day-from", "stream", "--birth-density", DENSITY, "--json", "--checkpoint",
         str(ck), *extra], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, env=_env())


def _write(proc: subprocess.Popen, data: bytes) -> threading.Thread:
    """Write ``data`` to ``proc``'s stdin from a thread, leaving it open (the feed goes
    on: no end of input)."""
    def feed() -> None:
        try:
            proc.stdin.write(data)
            proc.stdin.flush()
        except (BrokenPipeError, ValueError):  # killed while writing
            pass

    t = threading.Thread(target=feed)
    t.start()
    return t


@pytest.mark.parametrize("seed", [3, 11])
def test_kill_9_then_resume_keeps_the_track_ids(rec: Path, tmp_path: Path, seed: int) -> None:
    items = recording_datagrams(rec / "radar.ast")
    blocks = [d for d, _ in items]
    ref = _reference(rec, blocks)
    frames = sorted({r["frame"] for r in ref})
    t_first = min(r["time"] for r in ref)
    # the kill: at a seeded frame, once a few checkpoints were due (6 s of data each)
    late = [f for f in frames if min(r["time"] for r in ref if r["frame"] == f)
            > t_first + 20.0]
    rng = np.random.default_rng(seed)
    kill_frame = int(rng.choice(late[:int(0.7 * len(late))]))
    ck = tmp_path / "state.npz"
    a = _live(rec, ck, "--checkpoint-every", EVERY_MIN)
    feeder = _write(a, b"".join(blocks))
    first = []
    try:
        for line in a.stdout:  # bounded: the process ends at the latest with its input
            first.append(json.loads(line))
            if first[-1]["frame"] >= kill_frame:
                a.send_signal(signal.SIGKILL)
                break
    finally:
        if a.poll() is None:
            a.kill()
        a.wait()
        feeder.join()
        with contextlib.suppress(OSError):
            a.stdin.close()
        a.stdout.close()
        a.stderr.close()
    assert a.returncode == -signal.SIGKILL
    assert first == ref[:len(first)]  # the killed run was the reference until then
    kept = tmp_path / "kept.npz"
    shutil.copy(ck, kept)  # the last periodic checkpoint written before the kill
    tracker, state = read_checkpoint(kept)
    assert state.last_time is not None and t_first < state.last_time
    # the restart: the datagrams after the kill (those during the down time are lost);
    # the process may have gone on a few frames past the line read before SIGKILL came
    t_kill = max(state.last_time, max(r["time"] for r in first))
    rest = [d for d, t in items if t > t_kill]
    assert 0 < len(rest) < len(blocks)
    b = _live(rec, ck, "--resume")
    out, err = b.communicate(b"".join(rest))  # writes, closes and reads: to the end
    assert b.returncode == 0, err.decode()
    second = [json.loads(x) for x in out.splitlines()]
    assert second and min(r["frame"] for r in second) >= state.next_frame
    # the tracks confirmed at the checkpoint: those reported up to its last frame
    before = {r["track_id"] for r in ref if r["time"] <= state.last_time}
    carried = {r["track_id"] for r in second} & before
    t_end = max(r["time"] for r in ref)
    still = {r["track_id"] for r in ref if r["track_id"] in before
             and r["time"] > t_end - 12.0}  # reported in the last rotation
    assert still and still <= carried  # every aircraft still present keeps its id
    by_id: dict[int, list[dict]] = {}
    for r in ref:
        by_id.setdefault(r["track_id"], []).append(r)
    for r in second:
        if r["track_id"] not in before:
            assert r["track_id"] >= tracker.tracks.next  # a new track: a new id
            continue
        near = min(by_id[r["track_id"]], key=lambda q: abs(q["time"] - r["time"]))
        dt = r["time"] - near["time"]
        assert abs(dt) <= 12.0  # a rotation of the slowest radar
        assert np.hypot(near["x"] + near["vx"] * dt - r["x"],
                        near["y"] + near["vy"] * dt - r["y"]) < 1000.0, (r, near)
