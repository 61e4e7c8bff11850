"""Named clutter scenes for any scenario of rotating radars (``mhtrack simulate
--clutter-scene NAME``; ``docs/clutter.md``, *Clutter scenes*), and the ``radars-clutter``
preset they are studied on (``mhtrack reproduce clutter-scenes``). All values are ours.

A scene is laid out from the scenario itself — its region (width ``W``, height ``H``,
lower-left corner ``(x₀, y₀)``), its run ``[t_a, t_b]`` (length ``D``) and each radar's
site, ``max_range`` ``R`` and period ``P`` — so that it fits any number of radars at any
sites:

* ``weather`` — three rain cells drifting with one wind (:data:`WIND`, 20 m/s towards
  east-north-east), each σ₀ = 3 % of ``min(W, H)`` at its ``t_on``, growing by σ₀ every
  ``D`` (``g = σ₀/D``);
  cell 1 at ``(0.30 W, 0.60 H)`` at ``t_a`` (on before the run, fading by
  ``t_a + 0.7 D``), cell 2 at ``(0.50 W, 0.35 H)`` (from ``t_a + 0.2 D``), cell 3 at
  ``(0.70 W, 0.65 H)`` (from ``t_a + 0.4 D``); peaks 40, 30, 50 plots per rotation;
* ``coastal`` — ground clutter round every site (40 plots per rotation, ``L = 0.08 R``,
  three lobes, ripple 0.6) and a sea band on every radar (bearings 150°–240°, range
  ``0.6 R ± 0.08 R``) whose sea state rises from 10 to 40 plots per rotation between
  ``t_a + 0.2 D`` and ``t_a + 0.8 D``;
* ``burst`` — the ground clutter and a burst on the first radar (lowest id): 80 plots per
  rotation in the 20° sector from 60°, ranges ``0.1 R``–``0.9 R``, for three of its
  rotations from ``t_a + 0.5 D``;
* ``storm`` — all of the above together.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from mhtrack.models.clutter import Region, UniformClutter
from mhtrack.models.clutter_scene import (
    Burst,
    ClutterScene,
    GroundClutter,
    ScenePart,
    SeaBand,
    WeatherCell,
)
from mhtrack.models.sensors import RotatingRadar

#: Names accepted by :func:`clutter_scene`.
SCENES: tuple[str, ...] = ("weather", "coastal", "burst", "storm")
#: The wind that carries the weather cells (m/s, east and north).
WIND = (18.0, 8.7)
#: Weather cells: (x, y) as fractions of the region at t_a, on/off as fractions of the run,
#: peak plots per rotation.
WEATHER_CELLS = (((0.30, 0.60), (-0.3, 0.7), 40.0),
                 ((0.50, 0.35), (0.2, 1.2), 30.0),
                 ((0.70, 0.65), (0.4, 1.6), 50.0))
#: Ground clutter: plots per rotation, range scale L / R, ripple, lobes.
GROUND = (40.0, 0.08, 0.6, 3)
#: Sea band: plots per rotation (start, end), ramp (fractions of the run), range / R,
#: σ_range / R, first bearing (°), sector width (°).
SEA = ((10.0, 40.0), (0.2, 0.8), 0.6, 0.08, 150.0, 90.0)
#: Burst: plots per rotation, first bearing (°), width (°), ranges / R, rotations, start
#: (fraction of the run).
BURST = (80.0, 60.0, 20.0, (0.1, 0.9), 3, 0.5)


def _radars(scenario: Any) -> list[RotatingRadar]:
    radars = [s for s in scenario.sensors if isinstance(s, RotatingRadar)]
    if not scenario.rotating or not radars:
        raise ValueError(f"scenario {scenario.name!r}: clutter scenes are drawn by rotating "
                         "radars (sensors with a period)")
    for r in radars:
        if r.max_range is None:
            raise ValueError(f"sensor {r.id}: a clutter scene is laid out over the radar's "
                             "max_range; give it one")
    return sorted(radars, key=lambda r: r.id)


def _weather(scenario: Any) -> list[ScenePart]:
    reg: Region = scenario.region
    w, h = reg.xmax - reg.xmin, reg.ymax - reg.ymin
    ta, tb = scenario.first * scenario.T, scenario.last * scenario.T
    d = tb - ta
    sigma = 0.03 * min(w, h)
    parts = []
    for (fx, fy), (on, off), peak in WEATHER_CELLS:
        x, y = reg.xmin + fx * w - WIND[0] * ta, reg.ymin + fy * h - WIND[1] * ta
        parts.append(ScenePart(WeatherCell(x, y, WIND[0], WIND[1], sigma, sigma / d, peak,
                                           ta + on * d, ta + off * d)))
    return parts


def _ground(scenario: Any) -> list[ScenePart]:
    rate, scale, ripple, lobes = GROUND
    return [ScenePart(GroundClutter(rate, scale * _reach(r), ripple, lobes, 30.0 * r.id),
                      (r.id,)) for r in _radars(scenario)]


def _sea(scenario: Any) -> list[ScenePart]:
    (n0, n1), (u0, u1), rc, sr, bearing, width = SEA
    ta, tb = scenario.first * scenario.T, scenario.last * scenario.T
    d = tb - ta
    return [ScenePart(SeaBand(n0, n1, ta + u0 * d, ta + u1 * d, rc * _reach(r),
                              sr * _reach(r), bearing, width), (r.id,))
            for r in _radars(scenario)]


def _burst(scenario: Any) -> list[ScenePart]:
    rate, bearing, width, (lo, hi), rotations, start = BURST
    r = _radars(scenario)[0]
    ta, tb = scenario.first * scenario.T, scenario.last * scenario.T
    return [ScenePart(Burst(rate, ta + start * (tb - ta), rotations * r.period, bearing,
                            width, lo * _reach(r), hi * _reach(r)), (r.id,))]


def _reach(r: RotatingRadar) -> float:
    return float(r.max_range)  # type: ignore[arg-type]  # checked by _radars


def clutter_scene(name: str, scenario: Any) -> ClutterScene:
    """The named scene (:data:`SCENES`, module docstring) laid out for ``scenario``."""
    if name not in SCENES:
        raise ValueError(f"unknown clutter scene {name!r} (expected {', '.join(SCENES)})")
    parts = {"weather": (_weather,), "coastal": (_ground, _sea), "burst": (_ground, _burst),
             "storm": (_ground, _sea, _weather, _burst)}[name]
    return ClutterScene(name, tuple(p for f in parts for p in f(scenario)))


def with_clutter_scene(scenario: Any, name: str | None) -> Any:
    """``scenario`` with the named scene (``None``: unchanged); its name gets ``+NAME``."""
    if name is None:
        return scenario
    return dataclasses.replace(scenario, clutter_scene=clutter_scene(name, scenario),
                               name=f"{scenario.name}+{name}")


# ------------------------------------------------------------------ radars-clutter preset
#: Local frame origin (lat, lon) of ``radars-clutter`` (ours: a coast with sea to the south).
RADARS_CLUTTER_ORIGIN = (50.75, -1.30)
#: Radars: id, position (m), period (s), phase (°), σr (m), σθ (°), P_D, own uniform
#: clutter per rotation.
RADARS_CLUTTER_RADARS = ((1, (-15_000.0, 0.0), 4.0, 0.0, 40.0, 0.10, 0.9, 10.0),
                         (2, (20_000.0, 8_000.0), 6.0, 90.0, 60.0, 0.15, 0.85, 10.0))
RADARS_CLUTTER_RANGE = 50_000.0
#: Targets: state (x, vx, y, vy) at scan 0 (m, m/s), through every scan.
RADARS_CLUTTER_TARGETS = ((-50_000.0, 180.0, 20_000.0, -40.0),
                          (40_000.0, -150.0, 30_000.0, -90.0),
                          (-30_000.0, 120.0, -30_000.0, 110.0),
                          (10_000.0, 20.0, -40_000.0, 200.0),
                          (45_000.0, -200.0, -10_000.0, 30.0),
                          (-10_000.0, -60.0, 40_000.0, -160.0))
RADARS_CLUTTER_SCANS = 300


def radars_clutter(n_scans: int | None = None) -> Any:
    """The ``radars-clutter`` preset: two rotating radars (4 s and 6 s, 50 km reach, their
    own 10 uniform clutter plots per rotation) 37 km apart and six aircraft at
    120–200 m/s crossing their coverage, ``T = 1`` s, scans 0–299 (five minutes); no
    clutter scene (add one: :func:`with_clutter_scene`)."""
    from mhtrack.scenario.spec import Scenario
    from mhtrack.scenario.targets import Target

    last = (RADARS_CLUTTER_SCANS if n_scans is None else n_scans) - 1
    region = Region(-65_000.0, 70_000.0, -50_000.0, 58_000.0)
    radars = tuple(RotatingRadar(id=i, position=pos, period=p, phase=ph, sigma_range=sr,
                                 sigma_bearing_deg=sb, max_range=RADARS_CLUTTER_RANGE,
                                 clutter_rate=rate)
                   for i, pos, p, ph, sr, sb, _pd, rate in RADARS_CLUTTER_RADARS)
    return Scenario(
        name="radars-clutter",
        description=("Two rotating radars (4 s, 6 s; 50 km) 37 km apart and six aircraft "
                     "crossing their coverage; the clutter scenes of docs/clutter.md are "
                     "added with --clutter-scene (all ours)."),
        region=region, T=1.0, scans=(0, last),
        targets=tuple(Target(i, s, 0, last)
                      for i, s in enumerate(RADARS_CLUTTER_TARGETS, 1)),
        sensors=radars, pd=tuple(r[6] for r in RADARS_CLUTTER_RADARS),
        clutter=UniformClutter(region, 0.0), origin=RADARS_CLUTTER_ORIGIN, truth_dt=1.0)
