"""A headless Chromium driven over the Chrome DevTools protocol (CDP) through
``--remote-debugging-pipe`` (fd 3 commands in, fd 4 replies out, one JSON message per
NUL-terminated chunk): no websocket library and no open port needed.

:func:`check_page` opens a page (from disk or a loopback URL) and returns what the report
and live-view tests check: each Plotly figure's traces (given and drawn as SVG), the
console's errors and uncaught exceptions, every request that left the machine, and a PNG
screenshot of the whole page (the fixtures that skip where no Chromium is installed are
in ``tests/reports/conftest.py`` and the live view's test). Nothing here waits
for a time: every read blocks on the pipe until Chromium answers or exits (a Chromium
that dies closes the pipe, which fails the test).
"""

from __future__ import annotations

import base64
import contextlib
import fcntl
import json
import os
import shutil
import signal
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: Names of the Chromium executable, tried in order (Debian's package: ``chromium``).
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "chrome")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-default-apps", "--disable-extensions", "--mute-audio",
         "--remote-debugging-pipe")
#: The SVG groups of drawn traces: scatter (lines, markers) and bar (histograms).
TRACES = "'g.scatterlayer g.trace, g.barlayer g.trace'"
#: Per figure: its div id, traces given to Plotly, traces drawn in SVG, SVGs.
FIGURES_JS = """JSON.stringify(Array.from(document.querySelectorAll('div.plotly-graph-div'))
  .map(d => ({id: d.id, given: (d.data || []).length,
              drawn: d.querySelectorAll(TRACES_).length,
              svg: d.querySelectorAll('svg.main-svg').length,
              points: d.querySelectorAll('g.scatterlayer path.point').length})))"""
FIGURES_JS = FIGURES_JS.replace("TRACES_", TRACES)
#: A promise that resolves once every Plotly figure has drawn all its traces, then two
#: more animation frames (so the screenshot shows the finished page): the wait is for the
#: page's own event, not for a time. Its value: milliseconds since the navigation began
#: (the page's load time as the browser measured it, logged by the tests, never asserted).
DRAWN_JS = """new Promise(done => {
  const ready = () => Array.from(document.querySelectorAll('div.plotly-graph-div'))
    .filter(d => d.data !== undefined)  // Plotly.newPlot sets data during the page's load
    .every(d => d.querySelectorAll('svg.main-svg').length
                && d.querySelectorAll(TRACES_).length >= (d.data || []).length);
  const tick = () => ready()
    ? requestAnimationFrame(() => requestAnimationFrame(() => done(performance.now())))
    : requestAnimationFrame(tick);
  tick();
})"""
DRAWN_JS = DRAWN_JS.replace("TRACES_", TRACES)
#: Local schemes: anything else requested by the page went to the network.
LOCAL = ("file:", "data:", "about:", "blob:", "chrome:", "devtools:")


def chromium_path() -> str | None:
    """The first Chromium on ``PATH`` (``$MHTRACK_CHROMIUM`` first, when set)."""
    for name in (os.environ.get("MHTRACK_CHROMIUM"), *CHROMIUM_NAMES):
        if name and (path := shutil.which(name)):
            return path
    return None


@dataclass
class PageCheck:
    """What the browser saw: ``figures`` (see :data:`FIGURES_JS`), ``errors`` (console
    errors, uncaught exceptions, failed loads), ``requests`` (URLs outside
    :data:`LOCAL`), ``screenshot`` path."""

    figures: list[dict[str, Any]]
    errors: list[str] = field(default_factory=list)
    requests: list[str] = field(default_factory=list)
    screenshot: Path | None = None
    load_ms: float = float("nan")
    #: CPU seconds of Chromium's processes from the navigation until drawn (Linux's
    #: /proc; NaN elsewhere): the page's cost, less sensitive to a busy machine than
    #: ``load_ms``.
    cpu_s: float = float("nan")
    #: The value of the ``probe`` expression evaluated once the page was drawn.
    probe: Any = None


class Chromium:
    """One headless Chromium process and one page of it, over the CDP pipe."""

    def __init__(self, exe: str, profile: Path) -> None:
        cmd_r, cmd_w = os.pipe()
        out_r, out_w = os.pipe()
        hi = [fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10) for fd in (cmd_r, out_w)]
        for fd in (cmd_r, out_w):
            os.close(fd)
        self.log = open(profile.parent / "chromium.log", "wb")  # noqa: SIM115
        # the log first: its descriptor may be 3 or 4 (few files open), which the pipes
        # then take over
        actions = [(os.POSIX_SPAWN_DUP2, self.log.fileno(), 1),
                   (os.POSIX_SPAWN_DUP2, self.log.fileno(), 2),
                   (os.POSIX_SPAWN_DUP2, hi[0], 3), (os.POSIX_SPAWN_DUP2, hi[1], 4)]
        argv = [exe, *FLAGS, f"--user-data-dir={profile}", "about:blank"]
        self.pid = os.posix_spawn(exe, argv, os.environ, file_actions=actions,
                                  setpgroup=0)
        for fd in hi:
            os.close(fd)
        self.w, self.r = cmd_w, out_r
        self.buf = b""
        self.next_id = 0
        self.events: list[dict[str, Any]] = []
        self.session: str | None = None

    def send(self, method: str, params: dict[str, Any] | None = None) -> dict[str, Any]:
        """Send one command (to the page's session once attached); its result."""
        self.next_id += 1
        msg: dict[str, Any] = {"id": self.next_id, "method": method, "params": params or {}}
        if self.session is not None:
            msg["sessionId"] = self.session
        os.write(self.w, json.dumps(msg).encode() + b"\0")
        while True:
            reply = self._receive()
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"CDP {method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def _receive(self) -> dict[str, Any]:
        while b"\0" not in self.buf:
            chunk = os.read(self.r, 1 << 20)  # blocks until Chromium writes or exits
            if not chunk:
                raise ConnectionError("Chromium closed the pipe")
            self.buf += chunk
        msg, self.buf = self.buf.split(b"\0", 1)
        return json.loads(msg)

    def wait_event(self, method: str) -> dict[str, Any]:
        """The first event ``method`` (already received or coming)."""
        for e in self.events:
            if e.get("method") == method:
                return e
        while True:
            e = self._receive()
            self.events.append(e)
            if e.get("method") == method:
                return e

    def open(self, url: str, width: int) -> None:
        """Attach to a new page of ``width`` CSS pixels and load ``url``."""
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.send("Target.attachToTarget",
                                 {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Runtime", "Log", "Page", "Network"):
            self.send(f"{domain}.enable")
        self.send("Emulation.setDeviceMetricsOverride",
                  {"width": width, "height": 1000, "deviceScaleFactor": 1, "mobile": False})
        self.send("Page.navigate", {"url": url})
        self.wait_event("Page.loadEventFired")

    def evaluate(self, expression: str, *, await_promise: bool = False) -> Any:
        r = self.send("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                           "awaitPromise": await_promise})
        return r["result"].get("value")

    def screenshot(self, path: Path, width: int, most_height: int = 12000) -> Path:
        """The whole page (up to ``most_height`` pixels) as PNG."""
        height = self.send("Page.getLayoutMetrics")["cssContentSize"]["height"]
        shot = self.send("Page.captureScreenshot", {
            "format": "png", "captureBeyondViewport": True,
            "clip": {"x": 0, "y": 0, "width": width, "height": min(height, most_height),
                     "scale": 1}})
        path.write_bytes(base64.b64decode(shot["data"]))
        return path

    def problems(self) -> tuple[list[str], list[str]]:
        """(errors, network requests) among the events received so far."""
        errors, requests = [], []
        for e in self.events:
            m, p = e.get("method"), e.get("params", {})
            if m == "Runtime.exceptionThrown":
                d = p["exceptionDetails"]
                errors.append(d.get("exception", {}).get("description") or d.get("text", ""))
            elif m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                errors.append(" ".join(str(a.get("value", a.get("description", "")))
                                       for a in p.get("args", [])))
            elif m == "Log.entryAdded" and p["entry"].get("level") == "error":
                errors.append(p["entry"].get("text", ""))
            elif m == "Network.requestWillBeSent":
                url = p["request"]["url"]
                if not url.startswith(LOCAL):
                    requests.append(url)
        return errors, requests

    def close(self) -> None:
        """Ask Chromium to close; if it cannot answer (already gone, or the command
        failed), end its process group; then reap it."""
        try:
            self.session = None
            self.send("Browser.close")
        except (OSError, RuntimeError, ConnectionError):
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.pid, signal.SIGKILL)
        os.waitpid(self.pid, 0)
        for fd in (self.w, self.r):
            os.close(fd)
        self.log.close()


def process_group_cpu_s(pgid: int) -> float:
    """User + system CPU seconds of the live processes of group ``pgid`` (Linux /proc;
    NaN where there is none)."""
    proc = Path("/proc")
    if not proc.is_dir():
        return float("nan")
    ticks = 0
    for d in proc.iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat = (d / "stat").read_text()
        except OSError:
            continue
        f = stat[stat.rindex(")") + 2:].split()
        if int(f[2]) == pgid:  # fields after the name: state ppid pgrp ... utime stime
            ticks += int(f[11]) + int(f[12])
    return ticks / os.sysconf("SC_CLK_TCK")


def check_page(exe: str, page: Path, work: Path, *, width: int = 1400,
               probe: str | None = None) -> PageCheck:
    """Open ``page`` in headless Chromium, wait until Plotly has drawn every figure
    (:data:`DRAWN_JS`), evaluate ``probe`` (JavaScript) if given, and report (see
    :class:`PageCheck`); the screenshot goes to ``work/<page stem>.png``."""
    work.mkdir(parents=True, exist_ok=True)
    b = Chromium(exe, work / "profile")
    try:
        cpu0 = process_group_cpu_s(b.pid)
        b.open(page.resolve().as_uri(), width)
        load_ms = float(b.evaluate(DRAWN_JS, await_promise=True))
        cpu_s = process_group_cpu_s(b.pid) - cpu0
        figures = json.loads(b.evaluate(FIGURES_JS))
        value = None if probe is None else b.evaluate(probe, await_promise=True)
        shot = b.screenshot(work / f"{page.stem}.png", width)
        errors, requests = b.problems()
        return PageCheck(figures, errors, requests, shot, load_ms, cpu_s, value)
    finally:
        b.close()
