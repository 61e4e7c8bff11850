"""A live run's status for monitoring (``docs/live.md``, *Health and latency*): the
snapshot of :class:`~mhtrack.pipeline.health.Health` as a JSON file, as Prometheus text
(a file, or ``GET /metrics`` on a small HTTP endpoint of the standard library's
``http.server``, :class:`HttpEndpoint`, which also serves the live view).

Prometheus text exposition format 0.0.4 (Prometheus' *Exposition formats*): per metric a
``# HELP name text`` and a ``# TYPE name counter|gauge|summary`` line, then its samples
``name{label="value"} number``, one per line, the text ending with a newline; counters'
names end in ``_total``; a summary has its ``{quantile="0.5"}`` samples and its
``_sum`` and ``_count``. Served as ``text/plain; version=0.0.4; charset=utf-8``.
"""

from __future__ import annotations

import json
import math
import threading
from collections.abc import Callable, Mapping
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

from mhtrack.io.atomic import atomic_write
from mhtrack.io.jsonsafe import to_jsonable

#: Content type of the text format.
CONTENT_TYPE = "text/plain; version=0.0.4; charset=utf-8"
PREFIX = "mhtrack_live_"

#: (snapshot key, metric name, type, help) of the plain figures.
_PLAIN = (
    ("datagrams", "datagrams_total", "counter", "Datagrams received."),
    ("queue_drops", "queue_drops_total", "counter",
     "Datagrams dropped because the queue to the tracker was full."),
    ("kernel_drops", "kernel_drops_total", "counter",
     "Datagrams the kernel dropped for a full socket buffer (SO_RXQ_OVFL; NaN: not "
     "available on this system or input)."),
    ("plots", "plots_total", "counter", "Plots decoded and passed to the re-order window."),
    ("duplicates", "duplicates_total", "counter",
     "Data blocks received twice (redundant LANs) and dropped."),
    ("late_drops", "late_drops_total", "counter",
     "Plots dropped for arriving after the re-order window."),
    ("late_crossings", "late_crossings_total", "counter",
     "Sector crossings (CAT034/CAT002 sweep marks) dropped for arriving after the "
     "re-order window (not plots; their frames closed without them)."),
    ("frames", "frames_total", "counter", "Frames (sectors) tracked."),
    ("idle_closes", "idle_closes_total", "counter",
     "Times the feed was quiet for the idle wait and the frames held were closed."),
    ("tracks", "tracks", "gauge", "Confirmed tracks now."),
)


def _number(v: float) -> str:
    if math.isnan(v):
        return "NaN"
    if math.isinf(v):
        return "+Inf" if v > 0 else "-Inf"
    return repr(float(v)) if not float(v).is_integer() or abs(v) >= 1e15 else str(int(v))


def prometheus_text(snap: Mapping[str, Any]) -> str:
    """The snapshot in the text format 0.0.4 (module docstring)."""
    out: list[str] = []

    def metric(name: str, kind: str, text: str, samples: list[tuple[str, float]]) -> None:
        out.append(f"# HELP {PREFIX}{name} {text}")
        out.append(f"# TYPE {PREFIX}{name} {kind}")
        out.extend(f"{PREFIX}{name}{suffix} {_number(v)}" for suffix, v in samples)

    for key, name, kind, text in _PLAIN:
        v = snap.get(key)
        metric(name, kind, text, [("", math.nan if v is None else float(v))])
    metric("radars_silent", "gauge", "Radars silent for 3 rotation periods of data time.",
           [("", float(len(snap["radars_silent"])))])
    lat = snap["latency_s"]
    metric("latency_seconds", "summary", "From a sector's last datagram received to its "
           "output sent (last frames).",
           [('{quantile="0.5"}', lat["p50"]), ('{quantile="0.99"}', lat["p99"]),
            ("_sum", lat["sum"]), ("_count", float(lat["count"]))])
    return "\n".join(out) + "\n"


def write_status(snap: Mapping[str, Any], json_path: Path | None,
                 prometheus_path: Path | None) -> None:
    """The snapshot to a JSON file and/or a Prometheus text file, each atomically."""
    if json_path is not None:
        atomic_write(json_path, json.dumps(to_jsonable(dict(snap)), indent=1) + "\n")
    if prometheus_path is not None:
        atomic_write(prometheus_path, prometheus_text(snap))


#: What an :class:`HttpEndpoint` route returns: content type and body, made per request.
Route = Callable[[], tuple[str, bytes]]


def host_port(text: str, what: str = "endpoint") -> tuple[str, int]:
    """``HOST:PORT`` (``:PORT``: 127.0.0.1, the loopback interface only; IPv6 in
    brackets) of an HTTP endpoint; ``what`` names it in the error."""
    host, sep, port = text.rpartition(":")
    if not sep or not port.isdigit():
        raise ValueError(f"{text}: expected HOST:PORT for the {what}")
    return host.strip("[]") or "127.0.0.1", int(port)


class HttpEndpoint:
    """A small HTTP server (the standard library's ``http.server``) in a daemon thread
    on ``host:port`` (port 0: a free port, :attr:`address`): ``GET`` of a path of
    ``routes`` answers what its function makes now; any other path is a 404.
    :meth:`close` stops it."""

    def __init__(self, host: str, port: int, routes: Mapping[str, Route],
                 name: str = "mhtrack-http") -> None:
        paths = dict(routes)

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                route = paths.get(self.path.split("?")[0])
                if route is None:
                    self.send_error(404, "only " + ", ".join(sorted(paths)))
                    return
                kind, body = route()
                self.send_response(200)
                self.send_header("Content-Type", kind)
                self.send_header("Content-Length", str(len(body)))
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                self.wfile.write(body)

            def log_message(self, format: str, *args: Any) -> None:
                pass  # no line per request on stderr

        self._httpd = ThreadingHTTPServer((host, port), Handler)
        self._httpd.daemon_threads = True
        self.address = self._httpd.server_address[:2]
        self._thread = threading.Thread(target=self._httpd.serve_forever, name=name,
                                        daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._httpd.shutdown()
        self._httpd.server_close()
        self._thread.join()


class MetricsServer(HttpEndpoint):
    """``GET /metrics`` → the latest Prometheus text (:class:`HttpEndpoint`);
    :meth:`update` sets the text."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0) -> None:
        self._text = b""
        super().__init__(host, port, {"/metrics": lambda: (CONTENT_TYPE, self._text)},
                         "mhtrack-metrics")

    def update(self, text: str) -> None:
        self._text = text.encode()
