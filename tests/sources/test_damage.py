"""The damaged feed's rule (:mod:`mhtrack.sources.damage`): a small case worked by hand,
and over random schedules the send order against a sort of every copy by its due time
(the rule written the other way round), counts that add up, and the same copies damaged
for the same seed."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.sources.damage import Damage, DamageCounts, damaged


def _draws(seed: int, n: int, k: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.array([rng.random(k) for _ in range(n)])


def test_by_hand() -> None:
    # default_rng(3)'s first four draws, one a datagram (one destination)
    assert np.allclose(_draws(3, 4, 1)[:, 0], [0.0856, 0.2368, 0.8013, 0.5822], atol=1e-4)
    items = [(0, 0.0), (1, 1.0), (2, 2.0), (3, 3.0)]
    # drop 0.1: copy 0 (0.0856) is dropped; delay 0.2 (0.1 <= u < 0.3): copy 1 is late
    counts = DamageCounts()
    got = list(damaged(items, 1, Damage(0.1, 0.2, 1.5, 3), counts))
    assert got == [(2, 0, 2.0), (1, 0, 2.5), (3, 0, 3.0)]  # 1.0 + 1.5 s: between 2 and 3
    assert (counts.on_time, counts.delayed, counts.dropped) == (2, 1, 1)
    assert counts.per_destination == [[3, 1]]
    # late to exactly the time of copy 3: before it; later than everything: last
    assert list(damaged(items, 1, Damage(0.1, 0.2, 2.0, 3))) == [
        (2, 0, 2.0), (1, 0, 3.0), (3, 0, 3.0)]
    assert list(damaged(items, 1, Damage(0.1, 0.2, 9.0, 3))) == [
        (2, 0, 2.0), (3, 0, 3.0), (1, 0, 10.0)]


def test_no_damage_doubles_every_datagram_in_order() -> None:
    items = [(i, float(i // 3)) for i in range(10)]
    got = list(damaged(items, 2, Damage()))
    assert got == [(i, k, t) for i, t in items for k in (0, 1)]


@settings(max_examples=60, deadline=None)
@given(gaps=st.lists(st.integers(0, 3), min_size=1, max_size=60),
       dests=st.integers(1, 3), drop=st.floats(0, 0.5), delay=st.floats(0, 0.5),
       delay_s=st.integers(1, 5), seed=st.integers(0, 2**32))
def test_against_a_sort(gaps: list[int], dests: int, drop: float, delay: float,
                        delay_s: int, seed: int) -> None:
    due = np.cumsum(gaps).astype(float)
    items = list(enumerate(due.tolist()))
    counts = DamageCounts()
    got = list(damaged(items, dests, Damage(drop, delay, float(delay_s), seed), counts))
    u = _draws(seed, len(items), dests)
    want = []
    for i, t in items:
        for k in range(dests):
            if u[i, k] < drop:
                continue
            late = u[i, k] < drop + delay
            # a delayed copy goes before the on-time copies due with it; ties in draw order
            want.append((t + delay_s if late else t, 0 if late else 1, i * dests + k, i, k))
    want.sort()
    assert got == [(i, k, t) for t, _, _, i, k in want]
    n_drop = int((u < drop).sum())
    assert counts.dropped == n_drop and counts.on_time + counts.delayed == len(got)
    assert counts.delayed == int(((u >= drop) & (u < drop + delay)).sum())
    assert [sum(p) for p in counts.per_destination] == [len(items)] * dests
    assert got == list(damaged(items, dests, Damage(drop, delay, float(delay_s), seed)))


def test_bad_damage() -> None:
    for bad in ({"drop": 0.7, "delay": 0.4}, {"drop": -0.1}, {"delay_s": -1.0},
                {"delay_s": float("inf")}):
        with pytest.raises(ValueError):
            Damage(**bad)
    with pytest.raises(ValueError):
        list(damaged([(0, 0.0)], 0, Damage()))
