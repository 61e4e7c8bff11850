"""TOML files: the one reader (scenarios, configurations) and the scenario writer.

Read with :mod:`tomllib` (UTF-8, with or without a byte-order mark); written with
``tomli-w``, atomically, each array of plain values on one line (``[1.0, 2.5, 3.0]``; an
array of such arrays one row per line — :func:`compact_arrays`). Floats are written in
shortest round-trip form, so a written scenario reads back exactly. Every reading
problem is an :class:`~mhtrack.errors.InputError` in the one message style of
:mod:`mhtrack.errors`, ``<file>[, line L[, column C]]: <problem>``, e.g.
``s.toml, line 4, column 6: Expected '=' after a key in a key/value pair`` or
``s.toml, line 6: not valid UTF-8 text (byte 0xe9)``; a reader of the parsed dict reports
a bad value as ``<file>: <key path>: <problem>`` (:func:`key_error`).
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Mapping
from typing import Any

import numpy as np
import tomli_w

from mhtrack.bounds import MAX_NESTING, clip
from mhtrack.errors import InputError
from mhtrack.io._source import PathArg
from mhtrack.io.atomic import atomic_write
from mhtrack.io.paths import check_input_file

_AT = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")
#: One value tomli-w writes on its own line inside an array: a basic string (escaped, on
#: one line), a number, a boolean or a date — no array or inline table.
_SCALAR = r'(?:"(?:[^"\\\n]|\\.)*"|[^\s\[\]{},"\'#]+)'
#: A multi-line array of such values, as tomli-w writes it (items indented, one a line).
_ARRAY = re.compile(r"\[\n((?:[ ]+" + _SCALAR + r",\n)+)[ ]*\]")
#: A message that starts with a key path: ``T: …``, ``targets[2].birth: …``.
_KEY = re.compile(r"^[A-Za-z_][\w-]*(\[\d+\])*(\.[\w-]+(\[\d+\])*)*: ")


def read_toml(path: PathArg) -> dict[str, Any]:
    """Read a TOML file into a dict.

    Raises
    ------
    InputError : the file is missing, unreadable, not UTF-8, or not valid TOML — the
        message names the file and, for syntax errors, ``line L, column C``.
    """
    name = str(path)
    p = check_input_file(path)
    try:
        data = p.read_bytes()
    except OSError as e:
        raise InputError(f"{name}: cannot read ({e.strerror or e})", file=name) from None
    try:
        text = data.decode("utf-8-sig")  # a UTF-8 byte-order mark is accepted and dropped
    except UnicodeDecodeError as e:
        line = text_line(data, e.start)
        raise InputError(
            f"{name}, line {line}: not valid UTF-8 text (byte 0x{data[e.start]:02x})",
            file=name, line=line,
        ) from None
    try:
        data = tomllib.loads(text)
    except RecursionError:
        data = None
    except tomllib.TOMLDecodeError as e:
        message = str(e)
        m = _AT.search(message)
        if m:
            line = int(m[1])
            message = message[: m.start()]
            raise InputError(
                f"{name}, line {line}, column {m[2]}: {message}", file=name, line=line
            ) from None
        message = message.replace(" (at end of document)", "")
        raise InputError(f"{name}, end of file: {message}", file=name) from None
    key = None if data is None else too_deep(data)
    if data is None or key is not None:
        at = "" if key is None else f", key {clip(key, 60)!r}"
        raise InputError(f"{name}{at}: tables and arrays nested more than {MAX_NESTING} "
                         "levels deep", file=name, key=key)
    return data


def too_deep(value: Any, limit: int = MAX_NESTING) -> str | None:
    """The key path of the first value nested deeper than ``limit`` tables/arrays in
    ``value`` (parsed TOML or JSON), or ``None``; iterative, so it never recurses."""
    stack: list[tuple[Any, str, int]] = [(value, "", 0)]
    while stack:
        v, path, depth = stack.pop()
        if isinstance(v, dict | list):
            if depth > limit:
                return path or "(top level)"
            items = v.items() if isinstance(v, dict) else enumerate(v)
            for k, x in items:
                sub = f"{path}[{k}]" if isinstance(k, int) else f"{path}.{k}" if path else k
                stack.append((x, sub, depth + 1))
    return None


def key_error(path: PathArg, error: ValueError) -> InputError:
    """``<file>: <key path>: <problem>`` for a ``ValueError`` raised while reading the dict
    of the TOML file ``path`` (its message starts with the key path, e.g. ``T: must be
    > 0``); the key path is kept in :attr:`InputError.key`."""
    message = str(error)
    key = message.split(": ", 1)[0] if _KEY.match(message) else None
    return InputError(f"{path}: {message}", file=str(path), key=key)


def text_line(data: bytes, offset: int) -> int:
    """1-based line holding byte ``offset`` of ``data``."""
    return data.count(b"\n", 0, offset) + 1


def _plain(value: Any, key: str) -> Any:
    """NumPy scalars/arrays and tuples to plain Python; ``None`` (no TOML null) is an error."""
    if value is None:
        raise ValueError(f"scenario key {key!r} is None; TOML has no null value")
    if isinstance(value, Mapping):
        return {str(k): _plain(v, f"{key}.{k}" if key else str(k)) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, list | tuple):
        return [_plain(v, f"{key}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, np.generic):
        return value.item()
    return value


def compact_arrays(text: str) -> str:
    """``text`` (TOML as tomli-w writes it) with every array of plain values on one line,
    so an array of arrays has one row per line. The result parses to the same data as
    ``text`` (checked; ``text`` is returned unchanged otherwise, e.g. with a NaN, which
    equals nothing)."""
    def one_line(m: re.Match[str]) -> str:
        items = [ln.strip().removesuffix(",") for ln in m[1].splitlines()]
        return "[" + ", ".join(items) + "]"

    out = _ARRAY.sub(one_line, text)
    return out if tomllib.loads(out) == tomllib.loads(text) else text


def write_scenario_toml(data: Mapping[str, Any], path: PathArg) -> None:
    """Write ``data`` (nested dicts, lists, numbers, strings, booleans; NumPy values are
    converted) to the TOML file ``path``.

    Raises
    ------
    ValueError : a value is ``None`` (TOML has no null).
    TypeError : a value has a type TOML cannot hold.
    InputError : the file cannot be written.
    """
    plain = _plain(data, "")
    text = compact_arrays(tomli_w.dumps(plain))
    try:
        atomic_write(path, text, make_parent=False)
    except OSError as e:
        raise InputError(f"{path}: cannot write ({e.strerror or e})", file=str(path)) from None
