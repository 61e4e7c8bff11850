"""The live view of ``mhtrack live --view HOST:PORT`` (``docs/live.md``, *Live view*): one
local page showing the tracks, the radars and the status on a latitude/longitude grid,
updated every second.

Two parts, one per thread:

* :class:`ViewSink`, a sink in the pipeline's thread: after each frame it keeps, per
  track the best hypothesis reports now (``Leaves.reported``: chosen and confirmed), the
  track's latest reported row — position (WGS-84, through the tracker's local frame),
  speed ``√(vx² + vy²)``, heading ``atan2(vx, vy)`` (degrees clockwise from north), time,
  coasting, and from its attributes the flight level, Mode 3/A code and callsign when
  the plots had them — and its last :data:`TRAIL` positions. A track the tracker no
  longer reports leaves the view at that frame. :meth:`ViewSink.picture` copies that
  state under a lock, for the server's thread.
* :class:`ViewServer`, an :class:`~mhtrack.pipeline.monitor.HttpEndpoint`: ``GET /`` the
  page (``mhtrack/data/live_view.html``: plain HTML, CSS and JavaScript drawing SVG; no
  script, font or tile from elsewhere) and ``GET /view.json`` the current picture,
  radars and status (the same snapshot as ``--status-json``), which the page fetches
  every second.

The view only reads: the tracks, files and datagrams of a run are the same with or
without it.
"""

from __future__ import annotations

import json
import threading
from collections import deque
from collections.abc import Callable, Mapping
from importlib import resources
from typing import TYPE_CHECKING, Any

import numpy as np

from mhtrack.io.jsonsafe import to_jsonable
from mhtrack.pipeline.monitor import HttpEndpoint
from mhtrack.sinks.base import FrameOutput, Sink

if TYPE_CHECKING:
    from mhtrack.mht.tracker import MHTTracker
    from mhtrack.models.geodesy import LocalFrame
    from mhtrack.models.radars import SensorSet

#: Positions kept per track for its trail on the page.
TRAIL = 30
#: Points of each radar's reach circle.
REACH_POINTS = 73
#: The page (package data) and the JSON's path.
PAGE = "live_view.html"
JSON_PATH = "/view.json"


def radar_list(sensors: SensorSet) -> list[dict[str, Any]]:
    """The radars of ``sensors`` with a site: ``id, lat, lon, period`` (s or ``None``),
    ``reach_m`` and ``reach`` — the geodesic circle of that radius about the site as
    ``[lat, lon]`` points (WGS-84 direct problem), ``[]`` without a ``max_range``."""
    from mhtrack.models.geodesy import direct

    out = []
    for s in sensors.sensors:
        if s.lat is None or s.lon is None:
            continue
        reach = getattr(s, "max_range", None)
        ring: list[list[float]] = []
        if reach is not None and reach > 0:
            az = np.linspace(0.0, 360.0, REACH_POINTS)
            lat, lon = direct(np.full_like(az, s.lat), np.full_like(az, s.lon), az, reach)
            ring = np.round(np.column_stack([lat, lon]), 5).tolist()
        out.append({"id": int(s.id), "lat": float(s.lat), "lon": float(s.lon),
                    "period": None if s.period is None else float(s.period),
                    "reach_m": None if reach is None else float(reach), "reach": ring})
    return out


class ViewSink(Sink):
    """The tracks now, for the view (module docstring). ``tracker``: the pipeline's
    tracker (read after each frame, in the pipeline's thread); ``frame``: its local
    frame."""

    def __init__(self, tracker: Callable[[], MHTTracker], frame: LocalFrame,
                 trail: int = TRAIL) -> None:
        self._tracker, self._frame, self._trail = tracker, frame, int(trail)
        self._lock = threading.Lock()
        self._tracks: dict[int, dict[str, Any]] = {}
        self._trails: dict[int, deque[tuple[float, float]]] = {}
        self._last: dict[str, Any] = {"frame": None, "time": None}

    def write(self, out: FrameOutput) -> None:
        t = out.online
        rows: dict[int, dict[str, Any]] = {}
        if len(t):
            lat, lon = self._frame.to_geodetic(t.x, t.y)
            speed = np.hypot(t.vx, t.vy)
            heading = np.degrees(np.arctan2(t.vx, t.vy)) % 360.0
            a = t.attrs
            for i in range(len(t)):  # in report order: a track's last row wins
                row = {"id": int(t.track_id[i]), "lat": round(float(lat[i]), 6),
                       "lon": round(float(lon[i]), 6), "time": float(t.time[i]),
                       "speed": round(float(speed[i]), 2),
                       "heading": round(float(heading[i]), 1),
                       "coasting": bool(t.plot[i] < 0)}
                if a is not None:
                    row["flight_level"] = float(a.flight_level[i])
                    row["mode_3a"] = int(a.mode_3a[i])
                    row["callsign"] = str(a.callsign[i])
                rows[row["id"]] = row
        leaves = self._tracker().leaves
        now = set(np.unique(leaves.track[leaves.reported()]).tolist())
        with self._lock:
            for tid, row in rows.items():
                trail = self._trails.setdefault(tid, deque(maxlen=self._trail))
                trail.append((row["lat"], row["lon"]))
                self._tracks[tid] = row
            for tid in [k for k in self._tracks if k not in now]:
                del self._tracks[tid], self._trails[tid]
            self._last = {"frame": int(out.frame.index), "time": float(out.frame.time)}

    def picture(self) -> dict[str, Any]:
        """``frame`` and ``time`` of the last frame, and ``tracks``: one object per track
        reported now (by id), its ``trail`` of ``[lat, lon]`` oldest first."""
        with self._lock:
            tracks = [{**self._tracks[k], "trail": [list(p) for p in self._trails[k]]}
                      for k in sorted(self._tracks)]
            return {**self._last, "tracks": tracks}


def page_html() -> bytes:
    """The view's page (package data ``mhtrack/data/live_view.html``)."""
    return resources.files("mhtrack").joinpath("data", PAGE).read_bytes()


class ViewServer(HttpEndpoint):
    """``GET /`` the page, ``GET /view.json`` what ``state()`` returns now, as JSON
    (NaN and infinities as ``null``)."""

    def __init__(self, host: str, port: int, state: Callable[[], Mapping[str, Any]]
                 ) -> None:
        page = page_html()

        def as_json() -> tuple[str, bytes]:
            body = json.dumps(to_jsonable(dict(state())), separators=(",", ":"))
            return "application/json", body.encode()

        super().__init__(host, port, {"/": lambda: ("text/html; charset=utf-8", page),
                                      JSON_PATH: as_json}, "mhtrack-view")

    @property
    def url(self) -> str:
        host, port = self.address[0], self.address[1]
        return f"http://{f'[{host}]' if ':' in str(host) else host}:{port}/"
