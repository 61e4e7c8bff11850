"""Hostile saved states of the clutter map and the forgetting mixture: any value of any
field replaced either restores a working estimator (finite intensities ≥ 0 after one more
scan) or fails with ``ValueError`` naming the field — never another exception, never a
later failure."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.clutter.forgetting import ForgettingGMMClutter
from mhtrack.clutter.radar_map import ClutterMap
from mhtrack.records import Scan

BAD = [np.nan, np.inf, -np.inf, -1.0, 0.0, 1e300, -1e300, 1.5, 10**20, True, "x", None,
       [], [1.0, 2.0]]


def _scan(k: int, z: np.ndarray) -> Scan:
    return Scan(k, float(k), z, np.zeros(len(z), np.int64), np.arange(len(z)))


def _fed(make: Any) -> tuple[Any, np.ndarray]:
    rng = np.random.default_rng(0)
    est = make()
    for k in range(4):
        z = np.vstack([rng.normal((0, 0), 200, (15, 2)), rng.normal((2500, 800), 300, (15, 2)),
                       rng.uniform(-4000, 4000, (10, 2))])
        est.update(_scan(k, z))
    return est, rng.uniform(-4000, 4000, (30, 2))


MAKERS = {"map": lambda: ClutterMap(range_cell=500.0, n_azimuth=16),
          "fgmm": lambda: ForgettingGMMClutter()}


@pytest.mark.parametrize("name", list(MAKERS))
@given(data=st.data())
@settings(max_examples=60, deadline=None, derandomize=True, database=None)
def test_any_field_replaced_restores_or_names_the_field(name: str, data: st.DataObject) -> None:
    est, z = _fed(MAKERS[name])
    state = est.get_state()
    key = data.draw(st.sampled_from(sorted(state)))
    value = state[key]
    if isinstance(value, np.ndarray) and value.size:
        bad = value.copy()
        idx = data.draw(st.integers(0, bad.size - 1))
        bad.reshape(-1)[idx] = data.draw(st.sampled_from(
            [-5, -2, 10**15] if value.dtype.kind in "iu" else
            [np.nan, np.inf, -1.0, -1e300, 1e300]))
    else:
        bad = data.draw(st.sampled_from(BAD))
    fresh = MAKERS[name]()
    try:
        fresh.set_state({**state, key: bad})
    except ValueError as e:
        assert f"clutter_state.{key}" in str(e) or key in str(e), str(e)
        return
    fresh.update(_scan(9, z))
    k = fresh.intensity(z)
    assert np.isfinite(k).all() and (k >= 0).all()
