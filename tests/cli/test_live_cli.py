"""Acceptance (issue 30, first item, at small scale): ``mhtrack replay`` of an exported
opensky-radars recording into ``mhtrack live`` on 127.0.0.1, two processes; the CAT062
``live`` sends, decoded by an independent decoder (pyasteryx), equals the online view of
``mhtrack track`` on the same recording within one LSB — same frames, same rows.

Bounded by counts, not by the clock: ``live`` is stopped (SIGTERM) once ``replay`` has
exited, and drains what the kernel holds; every datagram sent must have been received
(else the test fails naming the loss — loopback UDP can drop under load), and every
CAT062 datagram ``live`` sent must be here."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")
pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx (extra [reference])")
pd = pytest.importorskip("pandas", reason="pandas (extra [pandas])")

from sim_recording import simulated_recording  # noqa: E402
from udp_drain import drain  # noqa: E402

from mhtrack.io.asterix.cat062 import lsb062  # noqa: E402

CLI = [sys.executable, "-c", "from mhtrack.cli.main import main; main()"]
DENSITY = "1e-10"  # live has no survey: both runs get the same new-target density


def _env() -> dict[str, str]:
    src = str(Path(__file__).resolve().parents[2] / "src")
    return {**os.environ, "PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(
        tmp_path_factory.mktemp("live"), seed=1, scans=8, name="radar.pcap",
        then=(["track", "{out}/radar.pcap", "--sensors", "{out}/sensors.toml", "--output",
               "online", "--birth-density", DENSITY, "--out", "{out}/online.csv"],))


def _drain(sock: socket.socket) -> list[bytes]:
    return drain(sock)


def test_replay_into_live_equals_track_online(recording: Path) -> None:
    diffs = replay_into_live(recording, "20")
    assert set(diffs) == {"lat", "lon", "vx", "vy", "time"}


def replay_into_live(recording: Path, speed: str) -> dict[str, float]:
    """Replay ``recording/radar.pcap`` at ``speed`` into ``live``; assert the CAT062
    equals ``recording/online.csv`` (module docstring); the largest difference of each
    column."""
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    rx.bind(("127.0.0.1", 0))
    live = subprocess.Popen(
        [*CLI, "live", "--listen", "udp://127.0.0.1:0", "--sensors",
         str(recording / "sensors.toml"), "--day-from", "stream", "--birth-density",
         DENSITY, "--out-udp", f"udp://127.0.0.1:{rx.getsockname()[1]}", "--out",
         str(recording / "live.ast")],
        stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, env=_env())
    try:
        first = live.stderr.readline()  # bound to port 0: live names the port it got
        m = re.match(r"listening on (udp://127\.0\.0\.1:\d+)$", first.strip())
        assert m, f"live did not start: {first!r}"
        sent = subprocess.run([*CLI, "replay", str(recording / "radar.pcap"), "--to",
                               m.group(1), "--speed", speed], capture_output=True, text=True,
                              env=_env(), check=True).stdout
        n_sent = int(re.search(r"sent (\d+) datagrams", sent).group(1))
        live.send_signal(signal.SIGTERM)  # replay is done: every datagram was delivered
        _, err = live.communicate()
    finally:
        if live.poll() is None:
            live.kill()
    assert live.returncode == 0, err
    summary = err.strip().splitlines()[-1]
    got = re.search(r"received (\d+) datagrams \((\d+) dropped in the queue\).*sent (\d+) "
                    r"CAT062 datagrams \((\d+) rows\)", summary)
    assert got, summary
    n_in, dropped, n_out, rows_out = map(int, got.groups())
    assert (n_in, dropped) == (n_sent, 0), f"UDP lost {n_sent - n_in} datagrams into live"
    cat062 = _drain(rx)
    rx.close()
    assert len(cat062) == n_out, f"UDP lost {n_out - len(cat062)} CAT062 datagrams"

    ref = pd.read_csv(recording / "online.csv")
    assert len(ref) == rows_out > 0
    recs = [[m.items for m in pyasteryx.Decoder().decode(d)] for d in cat062]
    # same frames: the datagrams split the rows only where the frames of track do
    # (a frame's rows go out together, 40 records at most a data block)
    bounds = np.cumsum([len(r) for r in recs]).tolist()
    frame_ends = np.flatnonzero(np.diff(ref["frame"].to_numpy())) + 1
    assert set(frame_ends.tolist()) | {len(ref)} <= set(bounds)
    assert all(b in set(frame_ends.tolist()) | {len(ref)} or (b - prev) == 40
               for prev, b in zip([0, *bounds], bounds, strict=False))
    # same rows, within one LSB; within a frame in (time in LSBs, track) order, the
    # encoder's order
    items = [r for d in recs for r in d]
    L = lsb062()
    tod = np.round(np.array([r["I062/070"]["ToT"] for r in items]) / L["tod_s"])
    tn = np.array([r["I062/040"]["TrkN"] for r in items])
    frame = ref["frame"].to_numpy()
    mine = np.lexsort((ref["track_id"].to_numpy(), np.round(ref["time"].to_numpy()
                                                             / L["tod_s"]), frame))
    theirs = np.lexsort((tn, tod, frame))  # the rows arrive frame by frame
    assert np.array_equal(tn[theirs], ref["track_id"].to_numpy()[mine])
    items = [items[i] for i in theirs]
    r = ref.iloc[mine]
    diffs = {}
    for key, sub, col, tol in (("I062/105", "Lat", "lat", L["deg"]),
                               ("I062/105", "Lon", "lon", L["deg"]),
                               ("I062/185", "Vx", "vx", L["mps"]),
                               ("I062/185", "Vy", "vy", L["mps"]),
                               ("I062/070", "ToT", "time", L["tod_s"])):
        diffs[col] = float(np.abs(np.array([x[key][sub] for x in items])
                                  - r[col].to_numpy()).max())
        assert diffs[col] <= tol, (col, diffs[col], tol)
    coasting = r["plot"].isna().to_numpy() | (r["plot"].fillna(0).to_numpy() < 0)
    assert [x["I062/080"]["CST"] for x in items] == coasting.astype(int).tolist()
    assert (recording / "live.ast").stat().st_size > 0
    return diffs


def _start_live(recording: Path, *extra: str) -> tuple[subprocess.Popen, str]:
    """``live`` on a free port with JSON lines on stdout; its endpoint."""
    live = subprocess.Popen(
        [*CLI, "live", "--listen", "udp://127.0.0.1:0", "--sensors",
         str(recording / "sensors.toml"), "--day-from", "stream", "--birth-density",
         DENSITY, "--json", *extra],
        stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=_env())
    for line in live.stderr:  # "resumed from ..." may come first
        m = re.match(r"listening on (udp://127\.0\.0\.1:\d+)$", line.strip())
        if m:
            return live, m.group(1)
        if not line.startswith("resumed from"):
            break
    live.kill()
    raise AssertionError(f"live did not start: {line!r}")


def _replay_then_sigterm(live: subprocess.Popen, to: str, recording: Path) -> list[dict]:
    """Replay ``recording`` into ``live``, then SIGTERM it; its JSON rows (every
    datagram sent must have been received)."""
    import json

    try:
        sent = subprocess.run([*CLI, "replay", str(recording), "--to", to, "--speed", "20"],
                              capture_output=True, text=True, env=_env(), check=True).stdout
        n_sent = int(re.search(r"sent (\d+) datagrams", sent).group(1))
        live.send_signal(signal.SIGTERM)
        out, err = live.communicate()
    finally:
        if live.poll() is None:
            live.kill()
    assert live.returncode == 0, err
    got = re.search(r"received (\d+) datagrams \((\d+) dropped", err)
    assert got and (int(got.group(1)), int(got.group(2))) == (n_sent, 0), err
    return [json.loads(x) for x in out.splitlines()]


def test_sigterm_midway_then_resume_equals_track(recording: Path, tmp_path: Path) -> None:
    """``live --checkpoint`` stopped by SIGTERM after the first half of the recording,
    then ``live --resume`` on the second half, stopped by SIGTERM too: the two runs' rows
    together are ``track --output online``'s on the whole recording — the same frames,
    track ids and positions (to the JSON lines' 1 mm) — up to the frames the last stop
    keeps in its checkpoint."""
    from mhtrack.sources.replay import recording_datagrams

    blocks = [d for d, _ in recording_datagrams(recording / "radar.pcap")]
    k = len(blocks) // 2
    (tmp_path / "a.ast").write_bytes(b"".join(blocks[:k]))
    (tmp_path / "b.ast").write_bytes(b"".join(blocks[k:]))
    ck = str(tmp_path / "state.npz")
    first = _replay_then_sigterm(*_start_live(recording, "--checkpoint", ck),
                                 tmp_path / "a.ast")
    second = _replay_then_sigterm(*_start_live(recording, "--checkpoint", ck, "--resume"),
                                  tmp_path / "b.ast")
    from mhtrack.pipeline.checkpoint import read_checkpoint

    # the second run's stop kept the plots of its open frames in the checkpoint (for a
    # third run): track's frames from there on come from plots live holds, not sent
    _, held = read_checkpoint(ck)
    assert held.pending is not None and held.pending["framed"] is not None
    ref = pd.read_csv(recording / "online.csv")
    assert ref["frame"].max() >= held.next_frame
    ref = ref[ref["frame"] < held.next_frame]
    rows = first + second
    assert len(first) > 0 and len(second) > 0
    assert [(r["frame"], r["track_id"]) for r in rows] == list(zip(
        ref["frame"].tolist(), ref["track_id"].tolist(), strict=True))
    for col in ("x", "y", "time"):  # (the file's vx, vy are east/north, not local)
        assert np.abs(np.array([r[col] for r in rows]) - ref[col].to_numpy()).max() <= 5e-4
