"""TrackTable.to_pandas() / from_pandas() (issue 31): a round trip gives the same table bit
for bit; the DataFrame's columns are the tracks file's; without pandas, one clear error."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from mhtrack.records import TrackTable


def _table(rng, with_optional):
    n = 7
    P = rng.normal(size=(n, 4, 4))
    return TrackTable(
        scan=rng.integers(0, 50, n), time=rng.normal(size=n) * 1e9, track_id=rng.integers(0, 9, n),
        x=rng.normal(size=n), y=rng.normal(size=n), vx=rng.normal(size=n),
        vy=rng.normal(size=n), plot=rng.integers(-1, 100, n),
        score=rng.normal(size=n) if with_optional else None,
        P=P if with_optional else None,
        tentative=rng.random(n) < 0.5 if with_optional else None)


@pytest.mark.parametrize("with_optional", [False, True])
def test_round_trip_is_bit_for_bit(with_optional):
    pytest.importorskip("pandas")
    t = _table(np.random.default_rng(3), with_optional)
    df = t.to_pandas()
    assert list(df.columns[:8]) == ["scan", "time", "track_id", "x", "y", "vx", "vy", "plot"]
    assert df["x"].tolist() == t.x.tolist() and len(df) == len(t)
    back = TrackTable.from_pandas(df)
    for f in t.__dataclass_fields__:
        a, b = getattr(t, f), getattr(back, f)
        assert (a is None) == (b is None), f
        if a is not None:
            assert a.dtype.kind == b.dtype.kind and a.tobytes() == b.tobytes(), f
    if with_optional:
        assert df["P12"].tolist() == t.P[:, 1, 2].tolist()  # row-major, as named


def test_missing_column_is_named():
    pd = pytest.importorskip("pandas")
    with pytest.raises(ValueError, match=r"lacks column.*vy"):
        TrackTable.from_pandas(pd.DataFrame({c: [0] for c in
                                             ("scan", "time", "track_id", "x", "y", "vx",
                                              "plot")}))


def test_without_pandas_one_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas raises ImportError
    t = _table(np.random.default_rng(0), False)
    with pytest.raises(ImportError, match=r"to_pandas needs pandas.*pip install pandas"):
        t.to_pandas()
    with pytest.raises(ImportError, match=r"from_pandas needs pandas"):
        TrackTable.from_pandas(object())
