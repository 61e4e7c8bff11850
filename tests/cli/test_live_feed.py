"""Damaged feed at small scale (issue 30's second acceptance; ``docs/live.md``, *A damaged
feed*): an exported ``opensky-radars`` recording (8 scans) replayed by ``mhtrack replay``
on two redundant LANs — two ports on 127.0.0.1 — into one ``mhtrack live``, two processes.

Checked by counts, not the clock: undamaged, ``live`` receives every datagram twice and
counts exactly one duplicate per datagram, and its rows equal ``track --output online``'s
on the recording; damaged (seeded drops and 3 s delays), the replay is first received by
the test's own two sockets (twice, the same copies each time: the seed fixes them), the
copies it counts there are those ``replay`` says it sent, and ``live``'s duplicates are
the copies received less the distinct datagrams among them."""

from __future__ import annotations

import itertools
import json
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
pd = pytest.importorskip("pandas", reason="pandas (extra [pandas])")

from udp_drain import drain  # noqa: E402

CLI = [sys.executable, "-c", "from mhtrack.cli.main import main; main()"]
DENSITY = "1e-10"
DAMAGE = ["--drop", "0.05", "--delay", "0.05:3", "--seed", "7"]


def _env() -> dict[str, str]:
    src = str(Path(__file__).resolve().parents[2] / "src")
    return {**os.environ, "PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    out = tmp_path_factory.mktemp("feed")
    for args in (["simulate", "opensky-radars", "--seed", "1", "--scans", "8", "--out",
                  str(out)],
                 ["export", str(out / "plots.csv"), "--sensors", str(out / "sensors.toml"),
                  "--out", str(out / "radar.pcap")],
                 ["track", str(out / "radar.pcap"), "--sensors", str(out / "sensors.toml"),
                  "--output", "online", "--birth-density", DENSITY, "--out",
                  str(out / "online.csv")]):
        r = CliRunner().invoke(cli, args)
        assert r.exit_code == 0, r.output
    return out


def _replay(path: Path, to: list[str], *extra: str) -> dict[str, int]:
    args = [*CLI, "replay", str(path), *[x for t in to for x in ("--to", t)], *extra]
    said = subprocess.run(args, capture_output=True, text=True, env=_env(),
                          check=True).stdout
    m = re.search(r"sent (\d+) datagrams", said)
    hurt = re.search(r"(\d+) copies dropped, (\d+) delayed", said)
    return {"sent": int(m.group(1)), "dropped": int(hurt.group(1)) if hurt else 0,
            "delayed": int(hurt.group(2)) if hurt else 0}


def _two_lans_into_live(recording: Path, *extra: str
                        ) -> tuple[dict[str, int], dict, list[dict]]:
    """``replay`` to two ports of one ``live`` (JSON lines, status file), SIGTERM once
    replay is done; replay's counts, live's status and its rows."""
    status = recording / "status.json"
    live = subprocess.Popen(
        [*CLI, "live", "--listen", "udp://127.0.0.1:0", "--listen", "udp://127.0.0.1:0",
         "--sensors", str(recording / "sensors.toml"), "--day-from", "stream",
         "--birth-density", DENSITY, "--json", "--status-json", str(status)],
        stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=_env())
    try:
        first = live.stderr.readline().strip()
        ports = re.findall(r"udp://127\.0\.0\.1:\d+", first)
        assert first.startswith("listening on") and len(ports) == 2, first
        sent = _replay(recording / "radar.pcap", ports, "--speed", "20", *extra)
        live.send_signal(signal.SIGTERM)  # loopback delivers at sendto: all is there
        out, err = live.communicate()
    finally:
        if live.poll() is None:
            live.kill()
    assert live.returncode == 0, err
    return sent, json.loads(status.read_text()), [json.loads(x) for x in out.splitlines()]


def _datagrams(recording: Path) -> list[bytes]:
    from mhtrack.sources.replay import recording_datagrams

    return [d for d, _ in recording_datagrams(recording / "radar.pcap")]


def test_two_lans_count_one_duplicate_per_datagram(recording: Path) -> None:
    n = len(_datagrams(recording))
    sent, status, rows = _two_lans_into_live(recording)
    assert sent == {"sent": 2 * n, "dropped": 0, "delayed": 0}
    assert (status["datagrams"], status["queue_drops"]) == (2 * n, 0), "loopback lost some"
    assert status["duplicates"] == n  # each export datagram is one data block
    assert status["late_drops"] == 0
    ref = pd.read_csv(recording / "online.csv")
    assert [(r["frame"], r["track_id"]) for r in rows] == list(zip(
        ref["frame"].tolist(), ref["track_id"].tolist(), strict=True))
    for col in ("x", "y", "time"):
        assert np.abs(np.array([r[col] for r in rows]) - ref[col].to_numpy()).max() <= 5e-4


def _received(recording: Path) -> tuple[dict[str, int], list[list[bytes]]]:
    socks = []
    for _ in range(2):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        s.bind(("127.0.0.1", 0))
        socks.append(s)
    try:
        sent = _replay(recording / "radar.pcap",
                       [f"udp://127.0.0.1:{s.getsockname()[1]}" for s in socks],
                       "--speed", "max", *DAMAGE)
        return sent, [drain(s) for s in socks]
    finally:
        for s in socks:
            s.close()


def test_damaged_feed_counted(recording: Path) -> None:
    blocks = _datagrams(recording)
    n = len(blocks)
    sent, got = _received(recording)
    again, got2 = _received(recording)
    assert got == got2 and sent == again  # the seed fixes the damaged copies
    received = sum(map(len, got))
    assert received == sent["sent"] == 2 * n - sent["dropped"], "loopback lost some"
    assert 0 < sent["dropped"] < 0.15 * 2 * n and 0 < sent["delayed"] < 0.15 * 2 * n
    index = {b: i for i, b in enumerate(blocks)}
    assert len(index) == n
    for lan in got:  # each LAN: a subset of the datagrams, those late out of place
        order = [index[b] for b in lan]
        assert len(set(order)) == len(order)
        assert sum(a > b for a, b in itertools.pairwise(order)) > 0
    distinct = len(set(got[0]) | set(got[1]))

    sent_live, status, rows = _two_lans_into_live(recording, *DAMAGE)
    assert sent_live == sent
    assert (status["datagrams"], status["queue_drops"]) == (received, 0)
    assert status["duplicates"] == received - distinct
    assert len(rows) > 0
