"""The NumPy CAT062 encoder (:mod:`mhtrack.io.asterix.cat062_fast`) against libasterix:
the same data blocks, octet for octet, for random rows (any time of day, positions over
the globe from one frame, velocities up to I062/185's range, track numbers 0–65535,
tentative and coasting rows, ties in time), and with attributes (any mix present and
absent, a hand-worked record, values beyond an item: the same refusal or, where the NumPy
encoder falls back, libasterix's own answer)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.attributes import TrackAttributes
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


def _attrs(rng: np.random.Generator, n: int, p: float) -> TrackAttributes:
    """Random attributes, each absent on a row with probability ``1 − p`` (values up
    to and at the items' limits: saturated ages, σ, ranges beyond 256 NM)."""
    def some(v: np.ndarray, absent: object) -> np.ndarray:
        return np.where(rng.random(n) < p, v, absent)

    chars = np.array(list("ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 "))
    names = ["".join(rng.choice(chars, rng.integers(1, 9))).lower() if rng.random() < p
             else "" for _ in range(n)]
    return TrackAttributes(
        flight_level=some(rng.uniform(-15, 1500, n), np.nan),
        rate_of_climb=some(rng.uniform(-2e5, 2e5, n), np.nan),
        mode_3a=some(rng.integers(0, 0o10000, n), -1),
        address=some(rng.integers(0, 1 << 24, n), -1),
        callsign=np.array(names, object),
        sigma_major=some(rng.uniform(0, 40_000, n), np.nan),
        sigma_minor=rng.uniform(0, 500, n), sigma_orient=rng.uniform(0, 180, n),
        sensors=np.full(n, "", object), sensor_ages=np.full(n, "", object),
        age_psr=some(rng.uniform(0, 80, n), np.nan),
        age_ssr=some(rng.uniform(0, 80, n), np.nan),
        age_mds=some(rng.uniform(0, 80, n), np.nan),
        meas_sensor=some(rng.integers(0, 0x10000, n), -1),
        meas_type=rng.integers(0, 6, n),
        meas_mode_3a=some(rng.integers(0, 0o10000, n), -1),
        meas_mode_3a_vg=rng.integers(0, 4, n),
        meas_flight_level=some(rng.uniform(-2047, 2047, n), np.nan),
        meas_flight_level_vg=rng.integers(0, 4, n),
        meas_range=some(rng.uniform(0, 520_000, n), np.nan),
        meas_bearing=some(rng.uniform(-360, 720, n), np.nan),
        existence_probability=some(rng.random(n), np.nan))


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 90), p=st.sampled_from(
    [0.0, 0.2, 0.5, 0.8, 1.0]), sac=st.integers(0, 255), sic=st.integers(0, 255))
def test_rows_with_attributes_same_octets_as_libasterix(seed: int, n: int, p: float,
                                                        sac: int, sic: int) -> None:
    """Any mix of present and absent attributes (p: the chance of each being present)."""
    frame = LocalFrame(50.0, 8.0)
    tracks = _table(seed, n, True)
    tracks = dataclasses.replace(tracks, attrs=_attrs(np.random.default_rng(seed), n, p))
    fast = list(blocks062(tracks, frame, "t", sac=sac, sic=sic))
    assert fast == _libasterix(tracks, frame, sac=sac, sic=sic)


def test_attribute_records_hand_worked() -> None:
    """One row, every attribute: the octets of I062/060, 245, 380, 290, 136, 220, 500
    and 340 worked out by hand from the edition 1.18 layouts."""
    tracks = dataclasses.replace(_table(5, 1, False), attrs=_attrs(
        np.random.default_rng(5), 1, 1.0))
    a = tracks.attrs
    a.mode_3a[0], a.address[0], a.callsign[0] = 0o1234, 0xABCDEF, "AZ09"
    a.flight_level[0], a.rate_of_climb[0] = -0.5, -6.25
    a.age_psr[0], a.age_ssr[0], a.age_mds[0] = 0.25, np.nan, 100.0
    a.sigma_major[0], a.sigma_minor[0], a.sigma_orient[0] = 3.0, 1.0, 90.0
    a.meas_sensor[0], a.meas_type[0] = 0x0102, 4
    a.meas_mode_3a[0], a.meas_mode_3a_vg[0] = 0o7777, 3
    a.meas_flight_level[0], a.meas_flight_level_vg[0] = -1.25, 2
    a.meas_range[0], a.meas_bearing[0] = 1852.0, 180.0
    rec = next(iter(blocks062(tracks, LocalFrame(48.0, 11.0), "t")))[2][3:]
    assert rec[:4] == bytes((0x9B, 0x7F, 0x25, 0x06))  # FRN 1 4 5 7 | 9-14 | 17 20 | 27 28
    body = rec[4 + 2 + 3 + 8 + 4:]
    chars = bytes.fromhex("05 ac 39 82 08 20")  # A Z 0 9 and four spaces, 6 bits each
    assert body[:2] == bytes.fromhex("02 9c")  # 060: code 1234 octal
    assert body[2:9] == b"\x00" + chars  # 245: STI 0, CHR
    assert body[9:19] == b"\xc0" + bytes.fromhex("ab cd ef") + chars  # 380: ADR, ID
    assert body[19 + 6:19 + 6 + 3] == bytes((0x50, 1, 0xFF))  # 290: PSR ¼ s, MDS 63.75 s
    assert body[28:32] == bytes.fromhex("ff fe ff ff")  # 136: −2 (¼ FL), 220: −1
    assert body[32:39] == bytes.fromhex("c0 00 06 00 02 00 00")  # 500: σx 3, σy 1 m, COV 0
    assert body[39:] == bytes.fromhex("dc 01 02 01 00 80 00 bf fb cf ff a0")  # 340


def _outcome(f) -> object:
    try:
        return f()
    except Exception as e:  # the outcome compared is the refusal itself
        return type(e), str(e)


@pytest.mark.parametrize("column, value", [
    ("flight_level", 1500.2), ("rate_of_climb", -210_000.0), ("callsign", "AB-1"),
    ("callsign", "ABCDEFGHI"), ("meas_flight_level", 2048.0), ("meas_sensor", 0x10000),
    ("mode_3a", 0o10000), ("address", 1 << 24), ("meas_mode_3a_vg", 4),
    ("meas_range", -5000.0)])
def test_attribute_values_beyond_an_item_same_outcome(column: str, value: object) -> None:
    """A value an item cannot hold: the same refusal as the libasterix path (the first
    six), or, where the NumPy encoder does not cover it, libasterix's own answer."""
    frame = LocalFrame(48.0, 11.0)
    tracks = dataclasses.replace(_table(6, 4, False),
                                 attrs=_attrs(np.random.default_rng(6), 4, 1.0))
    getattr(tracks.attrs, column)[2] = value
    fast = _outcome(lambda: list(blocks062(tracks, frame, "t")))
    assert fast == _outcome(lambda: _libasterix(tracks, frame))
    if column in ("flight_level", "rate_of_climb", "callsign", "meas_flight_level",
                  "meas_sensor"):
        assert fast[0] is ValueError and column in fast[1]  # type: ignore[index]
