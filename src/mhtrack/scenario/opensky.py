"""Recorded truth from the packaged OpenSky ADS-B data (``mhtrack/data``, see
``ATTRIBUTION.md``): 84 aircraft over southern England, 20 minutes on a 10 s grid.

Conversion (all our choices, documented in ``docs/scenarios.md``):

* positions: WGS-84 latitude/longitude → ECEF → local ENU about :data:`REFERENCE`
  (altitude ignored: every point is taken at ``h = 0``), keeping east → ``x`` and
  north → ``y`` (:mod:`mhtrack.scenario.geodesy`);
* velocities: ``x_speed`` is the east and ``y_speed`` the north component (m/s) in the
  aircraft's own local frame, rotated into the reference frame; vertical rate ignored;
* each row's position is the one reported at ``lastposupdate``; it is dead-reckoned along
  the row's velocity to the grid time, ``p(t) = p + v·(t − lastposupdate)`` (95 % of the
  rows are under 1.4 s old; ~5 % are the ghost tails OpenSky keeps for up to 300 s after
  last contact — drop those with ``max_position_age``);
* scans: ``scan = (time − t0)/10`` with ``t0`` = the first time of the file
  (:data:`T0`), so scans 0..120 at ``t = 10·scan`` s; an aircraft exists at a scan iff it
  has a row there;
* target ids: 1, 2, … in order of first appearance (ties in file order);
  :func:`aircraft_ids` maps id → ``icao24``.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.scenario.geodesy import geodetic_to_enu, local_to_reference_velocity
from mhtrack.scenario.targets import RecordedTarget

if TYPE_CHECKING:
    from mhtrack.models.geodesy import LocalFrame

#: Data file inside the package.
DATA_FILE = "opensky_plane_states.csv"
#: ENU reference point (lat, lon) in degrees: the data's mean latitude and longitude
#: (52.06699°, −1.45401°) rounded to 0.001° (our choice).
REFERENCE = (52.067, -1.454)
#: Unix time of the first row (scan 0) and the grid step (s).
T0 = 1626098400
PERIOD = 10.0


@dataclass(frozen=True)
class OpenSkyTruth:
    """The aircraft as rows (sorted by scan, then id): ``scan``, ``target_id``, ENU
    ``x, y`` (m) and ``vx, vy`` (m/s); ``icao24[i]`` is the transponder address of target
    id ``i + 1``; ``lat``/``lon`` the reported position of each row (degrees)."""

    scan: np.ndarray
    target_id: np.ndarray
    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    age: np.ndarray
    icao24: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.scan)

    def targets(self, first: int = 0, last: int | None = None) -> tuple[RecordedTarget, ...]:
        """One :class:`RecordedTarget` per aircraft with rows in ``[first, last]``."""
        last = int(self.scan.max()) if last is None else last
        keep = (self.scan >= first) & (self.scan <= last)
        out = []
        ids = self.target_id[keep]
        states = np.column_stack((self.x, self.vx, self.y, self.vy))[keep]
        scans = self.scan[keep]
        for tid in np.unique(ids).tolist():
            m = ids == tid
            out.append(
                RecordedTarget(tid, tuple(scans[m].tolist()), tuple(map(tuple, states[m].tolist())))
            )
        return tuple(out)


@lru_cache(maxsize=1)
def _read_rows() -> dict[str, np.ndarray]:
    text = resources.files("mhtrack").joinpath("data", DATA_FILE).read_text(encoding="utf-8")
    rows = list(csv.DictReader(io.StringIO(text)))
    cols: dict[str, np.ndarray] = {"icao24": np.array([r["icao24"] for r in rows])}
    for name in ("time", "lat", "lon", "x_speed", "y_speed", "lastposupdate"):
        cols[name] = np.array([float(r[name]) for r in rows])
    return cols


def load_opensky(
    max_position_age: float | None = None, frame: LocalFrame | None = None
) -> OpenSkyTruth:
    """Read the packaged CSV and convert it as described in the module docstring.

    Parameters
    ----------
    max_position_age : drop rows whose position is older than this (s) at the grid time
        (``time − lastposupdate``); ``None`` keeps every row (the default: an aircraft
        exists at a scan iff it has a row there).
    frame : instead of the ENU plane, put the aircraft in this azimuthal-equidistant
        :class:`~mhtrack.models.geodesy.LocalFrame` (pyproj): position
        ``frame.to_local(lat, lon)``, velocity ``frame.velocity_to_local`` (east/north
        → grid axes), then the same dead reckoning — the frame of rotating radars.
    """
    c = _read_rows()
    keep = np.ones(len(c["time"]), bool)
    age = c["time"] - c["lastposupdate"]
    if max_position_age is not None:
        if not (np.isfinite(max_position_age) and max_position_age >= 0):
            raise ValueError(f"max_position_age: must be >= 0, got {max_position_age}")
        keep = age <= max_position_age
    icao = c["icao24"][keep]
    lat, lon, time, age = c["lat"][keep], c["lon"][keep], c["time"][keep], age[keep]
    # ids in order of first appearance (rows are sorted by time; ties keep file order)
    names, first_row = np.unique(icao, return_index=True)
    order = np.argsort(first_row, kind="stable")
    rank = np.empty(len(names), np.int64)
    rank[order] = np.arange(1, len(names) + 1)
    tid = rank[np.searchsorted(names, icao)]

    if frame is None:
        enu = geodetic_to_enu(lat, lon, *REFERENCE)[:, :2]
        v = local_to_reference_velocity(c["x_speed"][keep], c["y_speed"][keep], lat, lon,
                                        *REFERENCE)
    else:
        enu = np.column_stack(frame.to_local(lat, lon))
        v = np.column_stack(frame.velocity_to_local(lat, lon, c["x_speed"][keep],
                                                    c["y_speed"][keep]))
    pos = enu + v * age[:, None]
    scan = np.rint((time - T0) / PERIOD).astype(np.int64)
    s = np.lexsort((tid, scan))
    return OpenSkyTruth(
        scan=scan[s],
        target_id=tid[s],
        x=pos[s, 0],
        y=pos[s, 1],
        vx=v[s, 0],
        vy=v[s, 1],
        lat=lat[s],
        lon=lon[s],
        age=age[s],
        icao24=tuple(names[order].tolist()),
    )


def aircraft_ids(max_position_age: float | None = None) -> dict[int, str]:
    """Target id → ``icao24`` of the OpenSky scenario."""
    return dict(enumerate(load_opensky(max_position_age).icao24, start=1))
