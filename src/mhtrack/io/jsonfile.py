"""Reading the JSON files mhtrack writes for itself (``montecarlo.json``, job records):
one object, checked, with every problem one :class:`~mhtrack.errors.InputError` line
``<file>, key '<field>': <what is wrong> (<what was expected>)``.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from os import PathLike
from typing import Any

from mhtrack.bounds import clip
from mhtrack.errors import InputError
from mhtrack.io.paths import check_input_file
from mhtrack.io.tomlfile import too_deep

#: Largest JSON file read (bytes): job records and study specs are a few kB.
MAX_JSON_BYTES = 64 << 20

def key_error(path: str | PathLike[str], key: str | None, problem: str) -> InputError:
    """``<file>, key '<key>': <problem>`` (``<file>: <problem>`` without a key)."""
    at = f", key {clip(key, 60)!r}" if key else ""
    return InputError(f"{path}{at}: {problem}", file=str(path), key=key)


def kind_of(v: object) -> str:
    """``object``, ``array``, ``string``, … as JSON names them."""
    return {dict: "object", list: "array", str: "string", bool: "boolean", int: "integer",
            float: "number", type(None): "null"}.get(type(v), type(v).__name__)


def read_json_object(path: str | PathLike[str], what: str,
                     required: Sequence[str] = ()) -> dict[str, Any]:
    """The JSON object in ``path`` (``what`` names the file's role in messages, e.g. "a
    Monte-Carlo study"); the ``required`` keys must be there.

    Raises
    ------
    InputError : not a regular file, larger than :data:`MAX_JSON_BYTES`, not JSON, nested
        too deep, not an object, or a required key missing.
    """
    p = check_input_file(path)
    if p.stat().st_size > MAX_JSON_BYTES:
        raise key_error(path, None, f"{p.stat().st_size} bytes, more than the "
                        f"{MAX_JSON_BYTES} a JSON file of {what} may hold")
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except UnicodeDecodeError as e:
        raise key_error(path, None, f"not valid UTF-8 text ({e.reason})") from None
    except RecursionError:
        raise key_error(path, None, "JSON nested too deep") from None
    except ValueError as e:
        raise key_error(path, None, f"not valid JSON ({clip(str(e), 120)})") from None
    except OSError as e:
        raise key_error(path, None, f"cannot read ({e.strerror or e})") from None
    if not isinstance(data, dict):
        raise key_error(path, None, f"expected a JSON object ({what}), got {kind_of(data)}")
    deep = too_deep(data)
    if deep is not None:
        raise key_error(path, deep, "JSON nested too deep")
    for key in required:
        if key not in data:
            raise key_error(path, key, f"missing (a JSON file of {what} has "
                            f"{', '.join(required)})")
    return data
