"""atomic_write / atomic_path and the JSON sanitiser."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mhtrack.io.atomic import atomic_path, atomic_write
from mhtrack.io.jsonsafe import dumps, to_jsonable


def test_atomic_write_replaces_whole_file(tmp_path: Path) -> None:
    p = tmp_path / "sub" / "a.txt"
    atomic_write(p, "old")
    atomic_write(p, "new ✓")
    assert p.read_text(encoding="utf-8") == "new ✓"
    assert [f.name for f in p.parent.iterdir()] == ["a.txt"]  # no temporary left


def test_atomic_path_keeps_old_file_on_error(tmp_path: Path) -> None:
    p = tmp_path / "a.bin"
    p.write_bytes(b"kept")
    with pytest.raises(RuntimeError), atomic_path(p) as tmp:
        tmp.write_bytes(b"half")
        raise RuntimeError("interrupted")
    assert p.read_bytes() == b"kept"
    assert [f.name for f in tmp_path.iterdir()] == ["a.bin"]


def test_to_jsonable_round_trips_through_json() -> None:
    obj = {1: (np.int64(3), np.float32(0.5), np.array([1.0, np.nan])), "b": [np.inf, True,
                                                                           np.bool_(False)]}
    out = to_jsonable(obj)
    assert out == {"1": [3, 0.5, [1.0, None]], "b": [None, True, False]}
    assert json.loads(dumps(obj)) == out
    assert to_jsonable(float("nan"), nonfinite_as_null=False) != to_jsonable(float("nan"))
    with pytest.raises(TypeError):
        to_jsonable({"x": object()}, strict=True)
