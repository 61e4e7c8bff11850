"""A surveillance network's scene: many rotating radars spread over a country-sized area
and many aircraft flying across it (the load of issue 30's national benchmark).

:func:`network_scenario` draws, from one seed:

* **radar sites** on a jittered grid over the area: the area is cut into ``nx × ny`` cells
  (``nx·ny >= n_radars``, cells as square as the area allows), the first ``n_radars``
  cells in a random order each get one site, uniform in the middle half of the cell — so
  the coverage overlaps as in a real network (each point seen by several radars) without
  clumping;
* each radar's **period** uniform in ``periods`` (s, rounded to 0.1 s: an en-route radar
  turns in 4–12 s), a random **phase**, its **reach** uniform in ``reach_m`` (the
  instrumented range: an en-route radar's 100–250 NM), range and azimuth noise uniform in
  ``sigma_range_m`` and ``sigma_bearing_deg``, ``P_D`` uniform in ``pd``, and
  ``clutter_per_s`` clutter plots per second uniform in range–azimuth (``clutter_per_s ×
  period`` per rotation, so fast and slow radars give the same clutter rate);
* **aircraft** in straight lines (constant velocity, the simulator's :class:`Target`),
  positions uniform over the area, headings uniform, ground speeds from two classes —
  ``cruise_share`` at cruise (210–250 m/s, about 410–490 kt at FL 300–400) and the rest
  climbing, descending or approaching (100–180 m/s); every aircraft flies for the whole
  run (some leave the covered area on the way: the count seen falls slowly).

The simulator is 2-D: the reach stands for the radar horizon at en-route flight levels
(an aircraft at FL 350 is above a radar's horizon out to about 400 km); lower aircraft are
not hidden nearer in. Sites are placed in the azimuthal-equidistant frame about the area's
centre ``origin`` and written as lat/lon (WGS-84).
"""

from __future__ import annotations

import math

import numpy as np

from mhtrack.models.clutter import Region, UniformClutter
from mhtrack.models.sensors import RotatingRadar
from mhtrack.scenario.spec import Scenario
from mhtrack.scenario.targets import Target

#: Ground speeds (m/s) of the two aircraft classes (ours): cruise, and climb/descent/approach.
CRUISE_SPEED = (210.0, 250.0)
TERMINAL_SPEED = (100.0, 180.0)


def _grid(n: int, width: float, height: float) -> tuple[int, int]:
    """``(nx, ny)`` with ``nx·ny >= n`` and cells as square as the area allows."""
    nx = max(1, round(math.sqrt(n * width / height)))
    ny = max(1, math.ceil(n / nx))
    return nx, ny


def radar_sites(rng: np.random.Generator, n: int, region: Region) -> np.ndarray:
    """``n`` sites ``(x, y)`` (m): one in each of ``n`` cells of a grid over ``region``
    picked at random, uniform in the middle half of its cell (module docstring)."""
    w, h = region.xmax - region.xmin, region.ymax - region.ymin
    nx, ny = _grid(n, w, h)
    cells = rng.permutation(nx * ny)[:n]
    cx, cy = cells % nx, cells // nx
    u = rng.uniform(0.25, 0.75, size=(n, 2))
    return np.column_stack((region.xmin + (cx + u[:, 0]) * w / nx,
                            region.ymin + (cy + u[:, 1]) * h / ny))


def aircraft_states(rng: np.random.Generator, n: int, region: Region,
                    cruise_share: float = 0.75) -> np.ndarray:
    """``n`` states ``[x, vx, y, vy]`` (m, m/s): uniform positions over ``region``,
    uniform headings, speeds from :data:`CRUISE_SPEED` with probability ``cruise_share``,
    else from :data:`TERMINAL_SPEED`."""
    x = rng.uniform(region.xmin, region.xmax, n)
    y = rng.uniform(region.ymin, region.ymax, n)
    heading = rng.uniform(0.0, 2.0 * np.pi, n)
    cruise = rng.random(n) < cruise_share
    speed = np.where(cruise, rng.uniform(*CRUISE_SPEED, n), rng.uniform(*TERMINAL_SPEED, n))
    return np.column_stack((x, speed * np.sin(heading), y, speed * np.cos(heading)))


def network_scenario(
    *, n_radars: int = 30, n_aircraft: int = 4000, size_m: tuple[float, float] = (1.2e6, 1.0e6),
    origin: tuple[float, float] = (46.5, 2.5), duration_s: int = 600,
    periods: tuple[float, float] = (4.0, 12.0), reach_m: tuple[float, float] = (180e3, 250e3),
    sigma_range_m: tuple[float, float] = (30.0, 80.0),
    sigma_bearing_deg: tuple[float, float] = (0.06, 0.15), pd: tuple[float, float] = (0.85, 0.97),
    clutter_per_s: float = 8.0, cruise_share: float = 0.75, seed: int = 0,
    name: str = "network",
) -> Scenario:
    """A scene of ``n_radars`` rotating radars and ``n_aircraft`` aircraft over a
    ``size_m`` (east, north) area centred on ``origin`` (lat, lon), for ``duration_s``
    seconds (truth every 1 s); every random choice from ``seed`` (module docstring).
    The simulation's own seed (:func:`~mhtrack.scenario.simulate`) draws detections,
    noise and clutter."""
    from mhtrack.models.geodesy import LocalFrame  # pyproj: imported only when used

    if n_radars < 1 or n_aircraft < 0 or duration_s < 1:
        raise ValueError("network_scenario: n_radars >= 1, n_aircraft >= 0 and "
                         f"duration_s >= 1 needed, got {n_radars}, {n_aircraft}, {duration_s}")
    rng = np.random.default_rng(seed)
    hx, hy = 0.5 * size_m[0], 0.5 * size_m[1]
    area = Region(-hx, hx, -hy, hy)
    sites = radar_sites(rng, n_radars, area)
    lat, lon = LocalFrame(*origin).to_geodetic(sites[:, 0], sites[:, 1])
    period = np.round(rng.uniform(*periods, n_radars), 1)
    radars = tuple(
        RotatingRadar(id=i + 1, lat=float(lat[i]), lon=float(lon[i]), period=float(period[i]),
                      phase=float(rng.uniform(0.0, 360.0)),
                      sigma_range=float(rng.uniform(*sigma_range_m)),
                      sigma_bearing_deg=float(rng.uniform(*sigma_bearing_deg)),
                      max_range=float(rng.uniform(*reach_m)),
                      clutter_rate=float(clutter_per_s * period[i]))
        for i in range(n_radars))
    pds = tuple(float(p) for p in rng.uniform(*pd, n_radars))
    states = aircraft_states(rng, n_aircraft, area, cruise_share)
    targets = tuple(Target(i + 1, tuple(s), 0, duration_s) for i, s in enumerate(states.tolist()))
    # the region holds the aircraft's whole flights (every state within it)
    reach = max(reach_m)
    pad = max(CRUISE_SPEED) * duration_s + reach
    region = Region(-hx - pad, hx + pad, -hy - pad, hy + pad)
    return Scenario(
        name=name,
        description=(f"{n_radars} rotating radars ({periods[0]:g}-{periods[1]:g} s) and "
                     f"{n_aircraft} aircraft over {size_m[0] / 1e3:g} x {size_m[1] / 1e3:g} km "
                     f"about lat/lon {origin}, scene seed {seed} "
                     "(mhtrack.scenario.network; all ours)"),
        region=region, T=1.0, scans=(0, duration_s), targets=targets, sensors=radars,
        pd=pds, clutter=UniformClutter(region, 0.0), origin=origin, truth_dt=1.0,
    )
