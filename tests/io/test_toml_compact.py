"""Scenario TOML files keep each array of plain values on one line (issue 31: the
``opensky-radars`` scenario was 43 305 lines, one number a line) and read back bit for bit."""

from __future__ import annotations

import math
import struct
import tomllib

import tomli_w
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.io import read_toml
from mhtrack.io.tomlfile import compact_arrays, write_scenario_toml
from mhtrack.scenario import load_scenario, preset


def _bits(v):
    """Values with each float as its 64 bits, so that == is bit-for-bit (−0.0 ≠ 0.0)."""
    if isinstance(v, dict):
        return {k: _bits(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_bits(x) for x in v]
    if isinstance(v, float):
        return ("f", struct.pack("<d", v))
    return (type(v).__name__, v)


def test_opensky_radars_scenario_is_compact_and_reads_back_bit_for_bit(tmp_path):
    sc = preset("opensky-radars")
    data = {"seed": 1, **sc.to_dict()}
    path = tmp_path / "scenario.toml"
    write_scenario_toml(data, path)
    lines = path.read_text().splitlines()
    # no array item on a line of its own: every line of plain values is a whole array
    lonely = [ln for ln in lines if ln.startswith(" ") and not ln.lstrip().startswith(("[", "{"))]
    assert lonely == []
    # as long as tomli-w's own layout reads, and far shorter
    assert _bits(read_toml(path)) == _bits(tomllib.loads(tomli_w.dumps(data)))
    assert len(lines) < len(tomli_w.dumps(data).splitlines()) / 5  # 6 672 against 43 305
    again = load_scenario(path)
    assert _bits({"seed": 1, **again.to_dict()}) == _bits(data)


scalars = st.one_of(st.integers(-2**63, 2**63 - 1), st.booleans(), st.text(max_size=12),
                    st.floats(allow_nan=False))
arrays = st.recursive(st.lists(scalars, max_size=6),
                      lambda inner: st.lists(inner, max_size=4), max_leaves=30)
keys = st.text(alphabet="abcxyz_", min_size=1, max_size=5)
documents = st.dictionaries(keys, st.one_of(scalars, arrays,
                                            st.dictionaries(keys, arrays, max_size=3)),
                            max_size=5)


@settings(max_examples=200, deadline=None)
@given(documents)
def test_compact_arrays_parse_to_the_same_data(doc):
    text = tomli_w.dumps(doc)
    out = compact_arrays(text)
    assert _bits(tomllib.loads(out)) == _bits(doc)
    assert out.count("\n") <= text.count("\n")


def test_a_nan_keeps_tomli_w_layout():
    text = tomli_w.dumps({"a": [1.0, math.nan]})
    assert compact_arrays(text) == text  # NaN equals nothing: the check keeps the original
