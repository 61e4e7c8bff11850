"""Property: any scenario or sensors TOML file either loads or raises
:class:`~mhtrack.errors.InputError` — never another exception (RecursionError, TypeError,
OverflowError, …). Inputs: arbitrary text, arbitrary TOML documents, and valid files with
one value replaced by an arbitrary TOML value."""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mhtrack.errors import InputError
from mhtrack.io.sensors import read_sensors
from mhtrack.scenario import load_scenario, preset

FUZZ = settings(derandomize=True, deadline=None, max_examples=60, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])

SENSORS = """[origin]
lat = 52.0
lon = 4.0

[[sensors]]
id = 1
kind = "polar"
pd = 0.9
position = [0.0, 0.0]
sigma_range = 50.0
sigma_bearing_deg = 0.5
period = 4.0
max_range = 100000.0
"""

scalars = st.one_of(
    st.booleans(), st.integers(-(2**63), 2**63 - 1), st.floats(), st.text(max_size=10),
    st.sampled_from([1e308, -1e308, 2**53 + 1, 10**18, 0, -1, 1e-320]),
)
values = st.recursive(scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text(min_size=1, max_size=6), inner,
                                                 max_size=4)), max_leaves=12)


def _leaves(d: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    if isinstance(d, dict):
        return [p for k, v in d.items() for p in _leaves(v, (*path, k))]
    if isinstance(d, list):
        return [p for i, v in enumerate(d) for p in _leaves(v, (*path, i))] or [path]
    return [path]


def _set(d: Any, path: tuple[Any, ...], value: Any) -> None:
    for k in path[:-1]:
        d = d[k]
    d[path[-1]] = value


def _scenario_dict() -> dict[str, Any]:
    return preset("crossing").to_dict()


def _sensors_dict() -> dict[str, Any]:
    import tomllib

    return tomllib.loads(SENSORS)


READERS: dict[str, tuple[Callable[[], dict[str, Any]], Callable[[Path], Any]]] = {
    "scenario": (_scenario_dict, load_scenario),
    "sensors": (_sensors_dict, read_sensors),
}


@pytest.fixture(scope="module")
def folder() -> Any:
    d = Path(tempfile.mkdtemp(prefix="mhtrack-toml-fuzz-"))
    yield d
    shutil.rmtree(d, ignore_errors=True)


def _load(reader: Callable[[Path], Any], path: Path) -> None:
    try:
        reader(path)
    except InputError as e:
        assert str(e).startswith(str(path)), str(e)


@pytest.mark.parametrize("kind", sorted(READERS))
@FUZZ
@given(text=st.text(max_size=200))
def test_any_text_loads_or_raises_input_error(folder: Path, kind: str, text: str) -> None:
    path = folder / f"{kind}.toml"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    _load(READERS[kind][1], path)


@pytest.mark.parametrize("kind", sorted(READERS))
@FUZZ
@given(doc=st.dictionaries(st.text(min_size=1, max_size=8), values, max_size=6))
def test_any_toml_document_loads_or_raises_input_error(folder: Path, kind: str,
                                                       doc: dict[str, Any]) -> None:
    path = folder / f"{kind}-doc.toml"
    try:
        path.write_text(tomli_w.dumps(doc))
    except (TypeError, ValueError):  # tomli-w cannot write it (e.g. NaN keys): no file
        return
    _load(READERS[kind][1], path)


@pytest.mark.parametrize("kind", sorted(READERS))
@FUZZ
@given(pick=st.integers(0, 10**6), value=values)
def test_one_value_replaced_loads_or_raises_input_error(folder: Path, kind: str, pick: int,
                                                        value: Any) -> None:
    make, reader = READERS[kind]
    d = make()
    leaves = _leaves(d)
    _set(d, leaves[pick % len(leaves)], value)
    path = folder / f"{kind}-one.toml"
    path.write_text(tomli_w.dumps(d))
    _load(reader, path)


@pytest.mark.parametrize("kind", sorted(READERS))
@pytest.mark.parametrize("nested", ["[" * 2000 + "]" * 2000, "{a=" * 300 + "1" + "}" * 300],
                         ids=["arrays", "tables"])
def test_deep_nesting_is_one_line(tmp_path: Path, kind: str, nested: str) -> None:
    path = tmp_path / "deep.toml"
    path.write_text(f"x = {nested}\n")
    with pytest.raises(InputError, match=r"nested more than 64 levels deep") as info:
        READERS[kind][1](path)
    assert "\n" not in str(info.value)
