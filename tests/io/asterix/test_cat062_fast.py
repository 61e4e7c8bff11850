"""The NumPy CAT062 encoder (:mod:`mhtrack.io.asterix.cat062_fast`) against libasterix:
the same data blocks, octet for octet, for random rows (any time of day, positions over
the globe from one frame, velocities up to I062/185's range, track numbers 0–65535,
tentative and coasting rows, ties in time), and the libasterix path kept for rows with
attributes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.io.asterix.cat062 import table_messages
from mhtrack.io.asterix.cat062_fast import blocks062
from mhtrack.io.asterix.encode import encode_blocks
from mhtrack.models.geodesy import LocalFrame
from mhtrack.records import TrackTable


def _table(seed: int, n: int, tentative: bool) -> TrackTable:
    rng = np.random.default_rng(seed)
    t = np.round(rng.uniform(0, 86_399, n) * 4) / 4  # quarter seconds: ties happen
    if n > 4:
        t[rng.integers(0, n, n // 4)] = t[0]
    return TrackTable(scan=np.zeros(n, np.int64), time=t,
                      track_id=rng.integers(0, 65536, n),
                      x=rng.uniform(-3e6, 3e6, n), y=rng.uniform(-3e6, 3e6, n),
                      vx=rng.uniform(-3000, 3000, n), vy=rng.uniform(-3000, 3000, n),
                      plot=np.where(rng.random(n) < 0.3, -1, rng.integers(0, 999, n)),
                      tentative=(rng.random(n) < 0.3) if tentative else None)


def _libasterix(tracks: TrackTable, frame: LocalFrame, **kw) -> list:
    return list(encode_blocks(table_messages(tracks, frame, "t", **kw)))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 130), tentative=st.booleans(),
       lat0=st.floats(-80, 80), lon0=st.floats(-180, 180),
       sac=st.integers(0, 255), sic=st.integers(0, 255))
def test_same_octets_as_libasterix(seed: int, n: int, tentative: bool, lat0: float,
                                   lon0: float, sac: int, sic: int) -> None:
    frame = LocalFrame(lat0, lon0)
    tracks = _table(seed, n, tentative)
    fast = list(blocks062(tracks, frame, "t", sac=sac, sic=sic))
    assert fast == _libasterix(tracks, frame, sac=sac, sic=sic)


def test_default_data_source_and_block_split() -> None:
    """No SAC/SIC: the default data source; 95 rows: blocks of 40, 40 and 15."""
    frame = LocalFrame(48.0, 11.0)
    tracks = _table(3, 95, True)
    fast = list(blocks062(tracks, frame, "t"))
    assert [len(b) for _, _, b in fast] == [3 + 40 * 25, 3 + 40 * 25, 3 + 15 * 25]
    assert fast == _libasterix(tracks, frame)


def test_rows_that_do_not_fit_are_refused_the_same() -> None:
    frame = LocalFrame(48.0, 11.0)
    tracks = _table(4, 5, False)
    tracks.track_id[2] = 70_000
    with pytest.raises(ValueError, match="track_id 70000 does not fit I062/040") as e:
        list(blocks062(tracks, frame, "t"))
    with pytest.raises(ValueError) as ref:
        _libasterix(tracks, frame)
    assert str(e.value) == str(ref.value)
