"""The dict (TOML) form of a :class:`~mhtrack.models.clutter_scene.ClutterScene`, both ways
(``docs/scenarios.md``, *Clutter scenes*)::

    [clutter_scene]
    name = "storm"
    [[clutter_scene.parts]]
    kind = "weather"      # weather, ground, sea or burst; the component's fields follow
    x = -20000.0  y = 5000.0  vx = 18.0  vy = 8.0  sigma = 3000.0  growth = 5.0
    peak = 40.0   t_on = -60.0  t_off = 420.0
    [[clutter_scene.parts]]
    kind = "ground"       radars = [1]    # optional: the radars that see it (default all)
    rate_per_rotation = 40.0  scale = 4000.0  ripple = 0.6  lobes = 3  phase_deg = 30.0

Errors name the key path, e.g. ``clutter_scene.parts[1].scale: must be > 0.0``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from mhtrack.models.clutter_scene import COMPONENT_KINDS, ClutterScene, ScenePart
from mhtrack.scenario import _check as ck

_KIND_OF = {cls: kind for kind, cls in COMPONENT_KINDS.items()}


def scene_to_dict(scene: ClutterScene) -> dict[str, Any]:
    """Dict form of ``scene`` (module docstring)."""
    parts = []
    for p in scene.parts:
        d: dict[str, Any] = {"kind": _KIND_OF[type(p.component)]}
        if p.radars is not None:
            d["radars"] = [int(i) for i in p.radars]
        d.update(dataclasses.asdict(p.component))
        parts.append(d)
    return {"name": scene.name, "parts": parts}


def scene_from_dict(d: Mapping[str, Any], path: str = "clutter_scene") -> ClutterScene:
    """A :class:`ClutterScene` from its dict form, every key validated."""
    t = ck.table(d, path)
    ck.keys(t, path, {"parts"}, {"name"})
    name = ck.string(t.get("name", "custom"), f"{path}.name")
    raw = t["parts"]
    if not isinstance(raw, list | tuple):
        raise ValueError(f"{path}.parts: expected a list, got {type(raw).__name__}")
    parts = []
    for i, p in enumerate(raw):
        pp = f"{path}.parts[{i}]"
        q = ck.table(p, pp)
        kind = q.get("kind")
        if kind not in COMPONENT_KINDS:
            raise ValueError(f"{pp}.kind: expected one of {', '.join(COMPONENT_KINDS)}, "
                             f"got {kind!r}")
        cls = COMPONENT_KINDS[kind]
        fields = dataclasses.fields(cls)
        required = {f.name for f in fields if f.default is dataclasses.MISSING}
        ck.keys(q, pp, required | {"kind"}, {f.name for f in fields} | {"radars"})
        kw: dict[str, Any] = {}
        for f in fields:
            if f.name not in q:
                continue
            key = f"{pp}.{f.name}"
            kw[f.name] = (ck.integer(q[f.name], key, lo=1) if f.name == "lobes"
                          else ck.number(q[f.name], key))
        radars = None
        if "radars" in q:
            ids = q["radars"]
            if not isinstance(ids, list | tuple) or not ids:
                raise ValueError(f"{pp}.radars: expected a non-empty list of sensor ids")
            radars = tuple(ck.integer(v, f"{pp}.radars[{j}]", lo=0) for j, v in enumerate(ids))
        with ck.at(pp):
            parts.append(ScenePart(cls(**kw), radars))
    return ClutterScene(name, tuple(parts))
