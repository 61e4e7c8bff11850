"""Registration biases given to a scenario's rotating radars (``mhtrack simulate --bias``).

A bias is written ``ID:range=200,gain=1.002,azimuth=-0.12``: radar ``ID`` reports
``r_m = gain · r + range`` (m) and ``θ_m = θ + azimuth`` (degrees) before its noise
(:class:`~mhtrack.models.sensors.RotatingRadar`, ``range_bias``, ``range_gain``,
``azimuth_bias_deg``). Keys left out keep the radar's value. The biases are written with
the scenario (``scenario.toml``), never in the sensors file a tracker reads.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

from mhtrack.models.sensors import RotatingRadar
from mhtrack.scenario.spec import Scenario

#: ``--bias`` keys → :class:`RotatingRadar` fields.
BIAS_FIELDS = {"range": "range_bias", "gain": "range_gain", "azimuth": "azimuth_bias_deg"}


def parse_bias(text: str) -> tuple[int, dict[str, float]]:
    """``"ID:key=value,…"`` → ``(ID, {field: value})``; ``ValueError`` names what is wrong."""
    sid, sep, rest = text.partition(":")
    if not sep or not sid.strip().lstrip("-").isdigit():
        raise ValueError(f"bias {text!r}: expected ID:range=M,gain=G,azimuth=DEG")
    out: dict[str, float] = {}
    for item in filter(None, (p.strip() for p in rest.split(","))):
        key, eq, value = item.partition("=")
        if not eq or key.strip() not in BIAS_FIELDS:
            raise ValueError(f"bias {text!r}: {item!r}: expected one of "
                             f"{', '.join(k + '=…' for k in BIAS_FIELDS)}")
        try:
            out[BIAS_FIELDS[key.strip()]] = float(value)
        except ValueError:
            raise ValueError(f"bias {text!r}: {key.strip()}: not a number: {value!r}") from None
    if not out:
        raise ValueError(f"bias {text!r}: no bias given")
    return int(sid), out


def with_biases(scenario: Scenario, biases: Iterable[tuple[int, dict[str, float]]]) -> Scenario:
    """``scenario`` with each ``(radar id, fields)`` set on its rotating radar
    (``ValueError`` for an unknown id or a radar that is not rotating)."""
    sensors = {s.id: s for s in scenario.sensors}
    for sid, fields in biases:
        s = sensors.get(sid)
        if not isinstance(s, RotatingRadar):
            raise ValueError(f"bias for sensor {sid}: no rotating radar has that id "
                             f"(radars: {', '.join(str(i) for i in sensors)})")
        sensors[sid] = dataclasses.replace(s, **fields)
    return dataclasses.replace(scenario, sensors=tuple(sensors[s.id] for s in scenario.sensors))
