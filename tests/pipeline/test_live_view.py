"""The live view (``mhtrack live --view``, :mod:`mhtrack.pipeline.view`): a small live run
over loopback UDP (127.0.0.1 only) with the view on 127.0.0.1, its JSON checked against
the run's own JSON lines, and its page opened in headless Chromium (tests/helpers/
browser.py), which must draw exactly the tracks and radars that the JSON lists, with no
error and nothing fetched from elsewhere.

Bounded by counts, not by the clock: every wait is a loop of at most a fixed number of
polls (or of the page's own redraws, one a second), and the run is stopped by its stop
event at the end."""

from __future__ import annotations

import io
import json
import math
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from browser import Chromium, chromium_path  # tests/helpers
from sim_recording import simulated_recording  # tests/helpers

from mhtrack.io.sensors import read_sensors
from mhtrack.pipeline import TrackOptions
from mhtrack.pipeline.live import Live, LiveOptions
from mhtrack.pipeline.monitor import host_port
from mhtrack.pipeline.view import TRAIL, page_html, radar_list
from mhtrack.sources.replay import replay

OPTIONS = TrackOptions(output="online", new_target_density=1e-10)
#: Polls of view.json (0.1 s apart) and redraws of the page waited for, at most.
POLLS, REDRAWS = 600, 30

#: In the page: wait (at most REDRAWS redraws) until it has drawn frame FRAME or a later
#: one; then what it drew — track and radar groups with their ids, the status table —
#: and the view JSON it drew them from, read in one go (the page's script cannot run in
#: between).
DRAWN_JS = """new Promise(done => {
  let seen = 0;
  const read = () => ({
    tracks: Array.from(document.querySelectorAll('#tracks g.track'))
      .map(g => ({id: Number(g.dataset.id), title: g.querySelector('title').textContent,
                  circles: g.querySelectorAll('circle').length})),
    radars: Array.from(document.querySelectorAll('#radars g.radar'))
      .map(g => Number(g.dataset.id)),
    grid: document.querySelectorAll('#grid line').length,
    status: Object.fromEntries(Array.from(document.querySelectorAll('#status tr'))
      .map(r => [r.cells[0].textContent, r.cells[1].textContent])),
    view: window.mhtrackView.last});
  const ok = () => window.mhtrackView && window.mhtrackView.last
    && window.mhtrackView.last.frame >= FRAME;
  if (ok()) { done(JSON.stringify(read())); return; }
  document.addEventListener('mhtrack-view-drawn', function wait() {
    seen += 1;
    if (ok() || seen >= REDRAWS) {
      document.removeEventListener('mhtrack-view-drawn', wait);
      done(JSON.stringify(read()));
    }
  });
})"""


def _get(url: str) -> dict[str, Any]:
    with urllib.request.urlopen(url, timeout=10) as r:  # 127.0.0.1 only
        assert r.headers["Content-Type"] == "application/json"
        return json.loads(r.read())


@pytest.fixture(scope="module")
def rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(tmp_path_factory.mktemp("view"), seed=1, scans=8)


def test_host_port_defaults_to_loopback() -> None:
    assert host_port(":8080") == ("127.0.0.1", 8080)
    assert host_port("[::1]:0") == ("::1", 0)
    with pytest.raises(ValueError, match="8080x: expected HOST:PORT for the view"):
        host_port("8080x", "view")


def test_radar_reach_is_a_geodesic_circle(rec: Path) -> None:
    """Each reach point lies ``max_range`` from the site (WGS-84 inverse problem)."""
    from mhtrack.models.geodesy import inverse

    sensors = read_sensors(rec / "sensors.toml")
    radars = radar_list(sensors)
    assert [r["id"] for r in radars] == [s.id for s in sensors.sensors]
    for r, s in zip(radars, sensors.sensors, strict=True):
        assert len(r["reach"]) > 10 and r["reach_m"] == s.max_range
        d, _ = inverse(r["lat"], r["lon"], *zip(*r["reach"], strict=True))
        assert max(abs(d - s.max_range)) < 1.0  # 1e-5° rounding: < 1 m


def test_page_is_self_contained() -> None:
    """The page loads nothing from elsewhere: no src or href but its own JSON."""
    page = page_html().decode()
    assert "src=" not in page and "http://" not in page.replace(
        'xmlns="http://www.w3.org/2000/svg"', "").replace(
        '"http://www.w3.org/2000/svg"', "")
    assert 'href="view.json"' in page


def test_live_view_shows_what_the_json_lists(rec: Path, tmp_path: Path) -> None:
    sensors = read_sensors(rec / "sensors.toml")
    out = io.StringIO()
    lines: list[str] = []
    up = threading.Event()

    def emit(line: str) -> None:
        lines.append(line)
        if line.startswith("view on "):
            up.set()

    stop = threading.Event()
    live = Live(sensors, OPTIONS, LiveOptions(
        listen=("udp://127.0.0.1:0",), day_from="stream", json=True, preload=False,
        view="127.0.0.1:0"), stop=stop, stdout=out, emit=emit)
    results: list[Any] = []
    runner = threading.Thread(target=lambda: results.append(live.run()))
    runner.start()
    try:
        assert up.wait(60), lines
        assert live.view_address[0] == "127.0.0.1"
        url = live.view_url
        sent = replay(rec / "radar.ast", live.listening, speed=50).datagrams
        # wait until every datagram is in and the tracker has stepped what it can
        # (the frame count stays put over five polls)
        frames: list[int] = []
        for _ in range(POLLS):
            v = _get(url + "view.json")
            if v["status"]["datagrams"] == sent:
                frames.append(v["status"]["frames"])
                if len(frames) >= 5 and len(set(frames[-5:])) == 1:
                    break
            time.sleep(0.1)
        else:
            pytest.fail(f"live did not settle: {v['status']}")
        assert v["tracks"] and v["frame"] == v["status"]["frames"] - 1
        assert len(v["tracks"]) == v["status"]["tracks"]  # the tracks reported now
        page = _open(url, tmp_path, v["frame"])
    finally:
        stop.set()
        runner.join()
    assert results, "live.run did not return"

    # the page drew exactly what its JSON lists, and that JSON is the settled one
    assert page["view"]["frame"] == v["frame"]
    assert [t["id"] for t in page["tracks"]] == [t["id"] for t in page["view"]["tracks"]]
    assert [t["id"] for t in page["view"]["tracks"]] == [t["id"] for t in v["tracks"]]
    assert all(t["circles"] == 1 and t["title"].startswith(f"track {t['id']}: ")
               for t in page["tracks"])
    assert page["radars"] == [s.id for s in sensors.sensors] and page["grid"] >= 2
    assert page["status"]["tracks"] == str(len(v["tracks"]))
    assert page["status"]["datagrams"] == str(sent)

    # each track of the view is the last row the run wrote for it (JSON lines) up to
    # the view's frame, and its trail the rows before, oldest first
    rows: dict[int, list[dict[str, Any]]] = {}
    for line in out.getvalue().splitlines():
        r = json.loads(line)
        if r["frame"] <= v["frame"]:
            rows.setdefault(r["track_id"], []).append(r)
    for t in v["tracks"]:
        mine = rows[t["id"]]
        last = mine[-1]
        assert t["coasting"] == last["coasting"]
        assert t["time"] == pytest.approx(last["time"], abs=1e-6)  # lines: to 1 µs
        assert abs(t["lat"] - last["lat"]) <= 1e-6 and abs(t["lon"] - last["lon"]) <= 1e-6
        assert t["speed"] == pytest.approx(math.hypot(last["vx"], last["vy"]), abs=0.01)
        heading = math.degrees(math.atan2(last["vx"], last["vy"])) % 360
        assert abs((t["heading"] - heading + 180) % 360 - 180) <= 0.05
        trail = [c for r in mine[-len(t["trail"]):] for c in (r["lat"], r["lon"])]
        assert len(t["trail"]) == min(len(mine), TRAIL)
        assert [c for p in t["trail"] for c in p] == pytest.approx(trail, abs=1e-6)


def _open(url: str, work: Path, frame: int) -> dict[str, Any]:
    """Open the view in headless Chromium; what it drew (:data:`DRAWN_JS`), after
    checking it logged no error and requested nothing but its own server."""
    exe = chromium_path()
    if exe is None:
        pytest.skip("no Chromium on PATH (apt-get install chromium, or set "
                    "MHTRACK_CHROMIUM): the live view is not checked in a browser")
    b = Chromium(exe, work / "profile")
    try:
        b.open(url, 1400)
        got = json.loads(b.evaluate(DRAWN_JS.replace("FRAME", str(frame))
                                    .replace("REDRAWS", str(REDRAWS)), await_promise=True))
        b.screenshot(work / "live-view.png", 1400)
        errors, requests = b.problems()
    finally:
        b.close()
    assert errors == [], errors
    assert {r.split("/")[2] for r in requests} <= {url.split("/")[2]}, requests
    return got


def test_cli_serves_the_view(rec: Path) -> None:
    """``mhtrack live --view 127.0.0.1:0``: stderr names the page; ``/`` is the page,
    ``/view.json`` lists the radars of the sensors file; SIGTERM ends it with status 0."""
    import os
    import signal
    import subprocess
    import sys

    src = str(Path(__file__).resolve().parents[2] / "src")
    env = {**os.environ, "PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}
    live = subprocess.Popen(
        [sys.executable, "-c", "from mhtrack.cli.main import main; main()", "live",
         "--listen", "udp://127.0.0.1:0", "--sensors", str(rec / "sensors.toml"),
         "--birth-density", "1e-10", "--view", "127.0.0.1:0"],
        stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, env=env)
    try:
        lines = [live.stderr.readline() for _ in range(2)]
        url = next((ln.split()[-1] for ln in lines if ln.startswith("view on ")), None)
        assert url is not None and url.startswith("http://127.0.0.1:"), lines
        with urllib.request.urlopen(url, timeout=10) as r:  # 127.0.0.1 only
            assert r.read() == page_html()
        v = _get(url + "view.json")
        assert [r["id"] for r in v["radars"]] == [
            s.id for s in read_sensors(rec / "sensors.toml").sensors]
        assert v["tracks"] == [] and v["frame"] is None
        live.send_signal(signal.SIGTERM)
        _, err = live.communicate(timeout=60)
    finally:
        if live.poll() is None:
            live.kill()
    assert live.returncode == 0, err
