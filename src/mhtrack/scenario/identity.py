"""Secondary-radar attributes for simulated plots (``mhtrack simulate --attributes``):
each aircraft's ICAO address, Mode 3/A code, identification and flight level, written on
its plots with the plot type, garbling and primary-only / secondary-only detections.

**Identities.** ``opensky`` and ``opensky-radars``: the data's own ``icao24`` address,
``squawk`` (the four octal digits; absent when the data has none), ``callsign`` and
barometric altitude (m → FL, interpolated in time; :func:`opensky_identities`). Other
scenarios: an address, a code and a constant flight level drawn per target
(:func:`drawn_identities`, stream ``(5, target)``; ours).

**Per detection** (stream ``(4, sensor, target)``, so that the plots' own draws are
untouched and a run without attributes is the run of before): primary only with
probability :attr:`AttributeOptions.psr_only` (no reply), secondary only with
:attr:`AttributeOptions.ssr_only` (a reply without a primary echo), else combined. A
reply carries the code and the level: Mode S in 25 ft steps (0.25 FL), Mode C in 100 ft
(1 FL); with probability :attr:`AttributeOptions.garble` its code has one of its 12 bits
flipped and its level a wrong value (FL + 1 to 50 either way), both flagged garbled (G),
as a radar's reply processor flags overlapping replies. Clutter plots are primary.

**Default.** :func:`default_attributes`: on for a scenario of rotating radars (civil
surveillance radars are secondary radars: their plots carry the replies), off otherwise
(the papers' scenarios: positions only). ``mhtrack simulate`` and ``run`` follow it
(``--attributes/--no-attributes``); the library's :func:`~mhtrack.scenario.simulate`
draws no attributes — :func:`with_attributes` adds them.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass, replace
from importlib import resources

import numpy as np

from mhtrack.attributes import (
    ABSENT,
    COMBINED,
    MODE_S,
    PRIMARY,
    SECONDARY,
    PlotAttributes,
    address_value,
)
from mhtrack.records import PlotTable
from mhtrack.scenario.simulate import Simulation
from mhtrack.scenario.spec import Scenario

#: One flight level (m): 100 ft.
FL_M = 30.48
#: Flight levels a plot may carry (I048/090's range, FL).
LEVELS = (-12.0, 1270.0)
_PLOT_STREAM = 4
_IDENTITY_STREAM = 5


@dataclass(frozen=True)
class AttributeOptions:
    """Probabilities per detection of a target (module docstring); defaults ours."""

    #: No reply: a primary-only plot (a missed interrogation or reply).
    psr_only: float = 0.05
    #: A reply without a primary echo: a secondary-only plot.
    ssr_only: float = 0.10
    #: A garbled reply: code and level flagged G, one code bit and the level wrong.
    garble: float = 0.02

    def __post_init__(self) -> None:
        for name in ("psr_only", "ssr_only", "garble"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0.0 <= v <= 1.0):
                raise ValueError(f"{name}: must be a probability in [0, 1], got {v!r}")
        if self.psr_only + self.ssr_only > 1.0:
            raise ValueError(f"psr_only + ssr_only = {self.psr_only + self.ssr_only:g} "
                             "exceeds 1")


@dataclass(frozen=True)
class Identity:
    """One aircraft: ``address`` (24 bits, ``-1`` none: Mode A/C only), ``code`` (12
    bits, ``-1`` none), ``callsign`` and its flight level (FL) at ``times`` (s, the
    scenario's time scale), interpolated between them (held beyond)."""

    address: int
    code: int
    callsign: str
    times: np.ndarray
    level: np.ndarray

    def level_at(self, t: np.ndarray) -> np.ndarray:
        return np.interp(t, self.times, self.level)


def _code(squawk: str) -> int:
    """The data's squawk (``"1174.0"``, ``"36.0"`` = 0036, empty) as a 12-bit code."""
    if squawk.strip() == "":
        return ABSENT
    digits = f"{int(float(squawk)):04d}"
    return int(digits, 8) if len(digits) == 4 and set(digits) <= set("01234567") \
        else ABSENT


def opensky_identities() -> dict[int, Identity]:
    """Target id (as :func:`mhtrack.scenario.opensky.load_opensky` numbers them) →
    :class:`Identity` from the packaged data; times ``t − T0`` (s), levels from
    ``baroaltitude`` (rows without it left out; an aircraft with none is at FL 0)."""
    from mhtrack.scenario.opensky import DATA_FILE, T0, load_opensky

    text = resources.files("mhtrack").joinpath("data", DATA_FILE).read_text(encoding="utf-8")
    rows = list(csv.DictReader(io.StringIO(text)))
    by: dict[str, list[dict[str, str]]] = {}
    for r in rows:
        by.setdefault(r["icao24"], []).append(r)
    out = {}
    for tid, icao in enumerate(load_opensky().icao24, start=1):
        mine = by[icao]
        alt = [(float(r["time"]) - T0, float(r["baroaltitude"]) / FL_M) for r in mine
               if r["baroaltitude"].strip()]
        t, h = (np.array(v, float) for v in zip(*alt, strict=True)) if alt else \
            (np.zeros(1), np.zeros(1))
        codes = [c for r in mine if (c := _code(r["squawk"])) >= 0]
        out[tid] = Identity(address_value(icao.upper()), codes[-1] if codes else ABSENT,
                            mine[-1]["callsign"].strip(), t, h)
    return out


def drawn_identities(target_ids: list[int], seed: int) -> dict[int, Identity]:
    """An address, a code and a constant level (FL 50–400 in steps of 10) per target,
    from stream ``(5, target)`` of ``seed`` (ours)."""
    out = {}
    for tid in target_ids:
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(
            _IDENTITY_STREAM, tid)))
        level = float(10 * rng.integers(5, 41))
        out[tid] = Identity(int(rng.integers(1, 1 << 24)), int(rng.integers(0, 1 << 12)),
                            f"SIM{tid:04d}", np.zeros(1), np.array([level]))
    return out


def add_attributes(plots: PlotTable, identities: dict[int, Identity],
                   options: AttributeOptions, seed: int) -> PlotTable:
    """``plots`` (with ``origin``) with :class:`~mhtrack.attributes.PlotAttributes` drawn
    as the module docstring says; positions and rows unchanged."""
    if plots.origin is None:
        raise ValueError("plots without origin: attributes are drawn per target")
    n = len(plots)
    cols = PlotAttributes.absent(n).columns(polar=True)
    if plots.range is not None and plots.bearing is not None:  # the measured position
        cols["polar_range"], cols["polar_bearing"] = plots.range, plots.bearing
    cols["plot_type"][:] = PRIMARY
    key = plots.sensor.astype(np.int64) * (1 << 32) + plots.origin
    target = plots.origin >= 0
    for k in np.unique(key[target]).tolist():
        rows = np.flatnonzero(key == k)
        sensor, tid = int(plots.sensor[rows[0]]), int(plots.origin[rows[0]])
        ident = identities.get(tid)
        if ident is None:
            continue
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(
            _PLOT_STREAM, sensor, tid)))
        u, garbled = rng.random(rows.size), rng.random(rows.size) < options.garble
        bit, error = rng.integers(0, 12, rows.size), rng.integers(1, 51, rows.size)
        sign = np.where(rng.random(rows.size) < 0.5, -1, 1)
        reply = u >= options.psr_only
        ssr_only = reply & (u < options.psr_only + options.ssr_only)
        kind = np.where(ssr_only, MODE_S if ident.address >= 0 else SECONDARY, COMBINED)
        cols["plot_type"][rows] = np.where(reply, kind, PRIMARY)
        step = 0.25 if ident.address >= 0 else 1.0
        level = np.round(ident.level_at(plots.time[rows]) / step) * step
        level = np.clip(np.where(garbled, level + sign * error, level), *LEVELS)
        cols["flight_level"][rows] = np.where(reply, level, np.nan)
        cols["flight_level_g"][rows] = reply & garbled
        if ident.code >= 0:
            code = np.where(garbled, ident.code ^ (1 << bit), ident.code)
            cols["mode_3a"][rows] = np.where(reply, code, ABSENT)
            cols["mode_3a_g"][rows] = reply & garbled
        if ident.address >= 0:
            cols["address"][rows] = np.where(reply, ident.address, ABSENT)
            cols["callsign"][rows] = np.where(reply, ident.callsign, "")
    return replace(plots, attrs=PlotAttributes.from_columns(cols, n))


#: The presets whose targets are the OpenSky data's aircraft (their own identities).
OPENSKY_PRESETS = ("opensky", "opensky-radars")


def base_name(name: str) -> str:
    """The scenario's name without the ``+SCENE`` a clutter scene adds
    (:func:`mhtrack.scenario.scenes.with_clutter_scene`): its data source."""
    return name.split("+", 1)[0]


def default_attributes(scenario: Scenario) -> bool:
    """Whether a simulation of ``scenario`` carries secondary-radar attributes unless told
    otherwise: with rotating radars (module docstring, "Default")."""
    return scenario.rotating


def with_attributes(sim: Simulation, options: AttributeOptions | None = None) -> Simulation:
    """``sim`` with its plots' attributes: the data's identities for the OpenSky presets
    (:func:`opensky_identities`), drawn ones otherwise (:func:`drawn_identities`);
    ``options`` default :class:`AttributeOptions`. Positions, times and origins unchanged
    (the attributes' draws have their own streams)."""
    options = AttributeOptions() if options is None else options
    ids = sorted(set(sim.truth.target_id.tolist()))
    identities = opensky_identities() if base_name(sim.scenario.name) in OPENSKY_PRESETS \
        else drawn_identities(ids, sim.seed)
    return replace(sim, plots=add_attributes(sim.plots, identities, options, sim.seed))
