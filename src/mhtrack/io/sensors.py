"""The sensors file (TOML): radar sites, errors, P_D, periods and ranges
(docs/file-formats.md, "Sensors file").

:func:`read_sensors` returns a :class:`~mhtrack.models.sensors.SensorSet`; every problem
raises :class:`~mhtrack.errors.InputError` with one line naming the file, the line and the
key, e.g. ``sensors.toml, line 9, key 'sensors[0].lat': latitude must be within [-90, 90]
degrees, got 95``. Syntax and encoding errors come from
:func:`~mhtrack.io.tomlfile.read_toml`. ``tomllib`` gives no positions for keys, so
:class:`_Locator` finds a key's line by scanning the text for table headers and
``key =`` lines (a key it cannot find — inside an inline table or a multi-line value — is
reported at its table's header line).
"""

from __future__ import annotations

import difflib
import re
from pathlib import Path
from typing import Any

import tomli_w

from mhtrack.bounds import MAX_INDEX, MAX_MAGNITUDE, clip, float_problem, int_problem
from mhtrack.errors import InputError
from mhtrack.io._source import PathArg
from mhtrack.io.atomic import atomic_write
from mhtrack.io.tomlfile import read_toml
from mhtrack.models.radars import (
    PLOT_TYPE_KEYS,
    PLOT_TYPE_NAMES,
    RadarSensor,
    SensorFieldError,
    SensorSet,
)

#: Keys of the ``[origin]`` table (both required).
ORIGIN_KEYS = ("lat", "lon")
#: Keys of a ``[[sensors]]`` table, required ones first.
REQUIRED_KEYS = ("id", "kind", "pd")
SENSOR_KEYS = (*REQUIRED_KEYS, "lat", "lon", "alt", "position", "sigma_range",
               "sigma_bearing_deg", "sigma", "period", "max_range", *PLOT_TYPE_NAMES)
_NUMBERS = ("lat", "lon", "alt", "pd", "sigma_range", "sigma_bearing_deg", "sigma",
            "period", "max_range")

_HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-]+)\s*\]\]?\s*(#.*)?$")
_KEY = re.compile(r"""^\s*(?:"([^"]*)"|'([^']*)'|([A-Za-z0-9_\-]+))\s*=""")


class _Locator:
    """Lines of the tables and keys of a TOML text: ``"origin"``, ``"sensors[i]"`` (the
    i-th ``[[sensors]]``, 0-based) and ``""`` (top level)."""

    def __init__(self, text: str) -> None:
        self.tables: dict[str, int] = {}
        self.keys: dict[tuple[str, str], int] = {}
        table, count = "", 0
        for number, line in enumerate(text.splitlines(), start=1):
            if m := _HEADER.match(line):
                name = m[2]
                if m[1] == "[[" and name == "sensors":
                    table, count = f"sensors[{count}]", count + 1
                elif name.startswith("sensors.") and count:  # [sensors.primary]: the last one's
                    table = f"sensors[{count - 1}]{name[len('sensors'):]}"
                else:
                    table = name
                self.tables.setdefault(table, number)
                self.keys.setdefault(("", name.split(".")[0]), number)
            elif m := _KEY.match(line):
                key = m[1] if m[1] is not None else m[2] if m[2] is not None else m[3]
                self.keys.setdefault((table, key), number)

    def line(self, where: str, key: str | None) -> int | None:
        """The key's line, else its table's header line, else the line that opens the
        table's top-level name (``sensors = [...]``), else None."""
        if key is not None and (where, key) in self.keys:
            return self.keys[where, key]
        if key is not None and f"{where}.{key}" in self.tables:  # [sensors.primary]
            return self.tables[f"{where}.{key}"]
        if where in self.tables:
            return self.tables[where]
        parent, dot, last = where.rpartition(".")
        if dot and (parent, last) in self.keys:  # an inline table: the line of its key
            return self.keys[parent, last]
        return self.keys.get(("", where.split("[")[0]))


class _Reader:
    def __init__(self, path: PathArg) -> None:
        self.name = str(path)
        self.data = read_toml(path)
        self.loc = _Locator(Path(path).read_bytes().decode("utf-8-sig"))

    def fail(self, where: str, key: str | None, message: str) -> InputError:
        line = self.loc.line(where, key)
        path = ".".join(p for p in (where, key) if p)
        at = f", line {line}" if line is not None else ""
        return InputError(f"{self.name}{at}, key '{path}': {message}", file=self.name,
                          line=line)

    def table(self, value: object, where: str, known: tuple[str, ...]) -> dict[str, Any]:
        """``value`` is a table whose keys are all in ``known``."""
        if not isinstance(value, dict):
            raise self.fail(where, None, f"expected a table, got {_describe(value)}")
        for key in value:
            if key not in known:
                close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
                hint = (f"did you mean '{close[0]}'?" if close
                        else f"known keys: {', '.join(known)}")
                raise self.fail(where, key, f"unknown key; {hint}")
        return value

    def number(self, t: dict[str, Any], where: str, key: str) -> float | None:
        v = t.get(key)
        if v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise self.fail(where, key, f"expected a number, got {_describe(v)}")
        x = float(v)  # TOML integers fit in a float
        if abs(x) > MAX_MAGNITUDE and x != float("inf") and x != -float("inf"):
            raise self.fail(where, key, str(float_problem(v)))  # NaN, inf: checked later
        return x

    def origin(self) -> tuple[float, float] | None:
        if "origin" not in self.data:
            return None
        t = self.table(self.data["origin"], "origin", ORIGIN_KEYS)
        for key in ORIGIN_KEYS:
            if key not in t:
                raise self.fail("origin", key, "missing")
        return self.number(t, "origin", "lat"), self.number(t, "origin", "lon")  # type: ignore[return-value]

    def sensor(self, value: object, i: int) -> RadarSensor:
        where = f"sensors[{i}]"
        t = self.table(value, where, SENSOR_KEYS)
        for key in REQUIRED_KEYS:
            if key not in t:
                raise self.fail(where, key, "missing (required for every sensor)")
        if isinstance(t["id"], bool) or not isinstance(t["id"], int):
            raise self.fail(where, "id", f"expected an integer, got {_describe(t['id'])}")
        if (problem := int_problem(t["id"], 0, MAX_INDEX)) is not None:
            raise self.fail(where, "id", problem)
        if not isinstance(t["kind"], str):
            raise self.fail(where, "kind", f"expected a string, got {_describe(t['kind'])}")
        fields: dict[str, Any] = {k: self.number(t, where, k) for k in _NUMBERS}
        if "position" in t:
            p = t["position"]
            if not (isinstance(p, list) and len(p) == 2 and all(
                    isinstance(v, int | float) and not isinstance(v, bool) for v in p)):
                raise self.fail(where, "position",
                                f"expected [x, y], two numbers, got {_describe(p)}")
            fields["position"] = (float(p[0]), float(p[1]))
        fields["plot_types"] = tuple(self.plot_type(t[name], f"{where}.{name}", name)
                                     for name in PLOT_TYPE_NAMES if name in t)
        try:
            return RadarSensor(t["id"], t["kind"], **fields)
        except SensorFieldError as e:
            head, dot, tail = e.key.partition(".")
            if dot:  # a plot type's key
                raise self.fail(f"{where}.{head}", tail, e.message) from None
            raise self.fail(where, e.key, e.message) from None

    def plot_type(self, value: object, where: str, name: str
                  ) -> tuple[str, float | None, float | None, float | None]:
        """One plot type's table (``[sensors.primary]`` or ``primary = {...}``): its keys
        are :data:`~mhtrack.models.radars.PLOT_TYPE_KEYS`, each optional."""
        t = self.table(value, where, PLOT_TYPE_KEYS)
        return (name, *(self.number(t, where, k) for k in PLOT_TYPE_KEYS))  # type: ignore[return-value]

    def read(self) -> SensorSet:
        self.table(self.data, "", ("origin", "sensors"))
        origin = self.origin()
        raw = self.data.get("sensors")
        if not isinstance(raw, list) or not raw:
            got = "missing" if raw is None else f"got {_describe(raw)}"
            raise self.fail("", "sensors", f"expected one or more [[sensors]] tables, {got}")
        sensors = tuple(self.sensor(s, i) for i, s in enumerate(raw))
        try:
            return SensorSet(origin, sensors)
        except SensorFieldError as e:
            where = "origin" if e.index is None else f"sensors[{e.index}]"
            raise self.fail(where, e.key, e.message) from None


def _describe(v: object) -> str:
    kinds = {str: "string", dict: "table", list: "array", bool: "boolean", int: "integer",
             float: "float"}
    text = clip(repr(v)) if not isinstance(v, dict | list) or len(repr(v)) < 40 else "…"
    return f"{kinds.get(type(v), type(v).__name__)} {text}"


def read_sensors(path: PathArg) -> SensorSet:
    """Read and validate a sensors file.

    Raises
    ------
    InputError : one line naming the file, the line and the key of the first problem.
    """
    return _Reader(path).read()


def sensors_to_dict(sensors: SensorSet) -> dict[str, Any]:
    """The TOML form of ``sensors`` (keys left unset are omitted)."""
    out: dict[str, Any] = {}
    if sensors.origin is not None:
        out["origin"] = {"lat": sensors.origin[0], "lon": sensors.origin[1]}
    out["sensors"] = []
    for s in sensors.sensors:
        d: dict[str, Any] = {"id": s.id, "kind": s.kind}
        for key in SENSOR_KEYS[2:]:
            if key in PLOT_TYPE_NAMES:
                continue
            v = getattr(s, key)
            if v is not None:
                d[key] = list(v) if key == "position" else v
        for name, *values in s.plot_types:
            d[name] = {k: v for k, v in zip(PLOT_TYPE_KEYS, values, strict=True)
                       if v is not None}
        out["sensors"].append(d)
    return out


def write_sensors(sensors: SensorSet, path: PathArg) -> None:
    """Write ``sensors`` as a sensors file that :func:`read_sensors` reads back equal."""
    atomic_write(path, tomli_w.dumps(sensors_to_dict(sensors)))
