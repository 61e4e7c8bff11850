"""CAT001/CAT002 plots with their time of day restored, CAT021 ADS-B reports with σ from
NACp/NUCp, CAT062 tracks as a reference with impossible values refused: round trips
through encode_other.py, checked against hand-built octets (CAT001/002, which pyasteryx
does not read), pyasteryx (CAT021) and closed forms (σ of a 95 % radius)."""

from __future__ import annotations

import itertools
import math
import struct
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.stats import chi2

from mhtrack.io.asterix import cat001, cat021, encode_other, wrap
from mhtrack.io.asterix.cat062 import read_system_tracks
from mhtrack.io.asterix.encode import Message, encode_blocks
from mhtrack.io.asterix.framings import units
from mhtrack.io.asterix.notplots import real_plots
from mhtrack.io.asterix.problems import Problems

NM = 1852.0


def test_cat001_hand_built_octets() -> None:
    """A CAT002 north marker and two CAT001 records built octet by octet from the
    category's layout (FSPEC, then the items), not by libasterix."""
    # CAT002: FSPEC 1101 0000 = I002/010, 000, 030 (FRN 1, 2, 4); SAC 7 SIC 9; type 1;
    # time of day 3 600 s = 460 800 /128
    cat2 = bytes([0b11010000, 7, 9, 1]) + (3600 * 128).to_bytes(3, "big")
    # CAT001 plot: FSPEC 1111 1011, 0000 0000? no: FRN 1-5 (010, 020, 040, 070, 090),
    # FRN 7 (141), FX 0 → 1111 1010. I001/020 0011 0001 (TYP 0 plot, SSR/PSR 3, FX),
    # 1000 0000 (TST). RHO 12 800 = 100 NM, THETA 16 384 = 90°; Mode 3/A 7 7 0 0 octal;
    # HGT 1 400 = 350 FL; I001/141 = (3 610 s × 128) mod 65 536
    trunc = (3610 * 128) % 65536
    plot = bytes([0b11111010, 7, 9, 0b00110001, 0b10000000]) + struct.pack(
        "!HHHHH", 12800, 16384, 0o7700, 1400, trunc)
    # and a track: I001/020 TYP 1 (1010 0000, no FX): FSPEC 1100 0000 (010, 020 only)
    track = bytes([0b11000000, 7, 9, 0b10100000])
    restorer, problems = cat001.TimeRestorer(), Problems()
    marks = cat001.block002(cat2, restorer)
    assert marks == [(3600.0, 7 * 256 + 9, 1, pytest.approx(np.nan, nan_ok=True),
                      pytest.approx(np.nan, nan_ok=True))]
    rows = cat001.block001(plot + track, 0, None, restorer, problems)
    assert rows is not None and len(rows) == 1  # the track has no position: not a plot
    r = dict(zip(cat001.COLUMNS, rows[0], strict=True))
    assert r["time"] == 3610.0 and r["sensor"] == 7 * 256 + 9
    assert r["slant_range"] == 100 * NM and r["bearing"] == 90.0
    assert r["mode_3a"] == "7700" and r["flight_level"] == 350.0
    assert (r["typ"], r["plot_type"], r["tst"], r["track"]) == (3, 3, 1, 0)
    assert problems.counts == {"no_position": 1}


def _scene(n: int = 400, period: float = 4.0, t0: float = 86400 - 700.0
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One radar's plots over ~25 min across midnight (time of day, slant, bearing)."""
    rng = np.random.default_rng(3)
    t = np.sort(t0 + rng.uniform(0, 1500, n))
    return t, rng.uniform(1e3, 3e5, n), np.mod(t / period * 360.0, 360.0)


def _cat001_file(t: np.ndarray, slant: np.ndarray, bearing: np.ndarray, *,
                 marks: bool, typ: np.ndarray | None = None) -> tuple[bytes, list[float]]:
    msgs = [(float(t[i]), 513, 1, encode_other.plot001(
        t[i], 513, slant[i], bearing[i], typ=3 if typ is None else int(typ[i])))
        for i in range(t.size)]
    if marks:
        msgs += [(float(m), 513, 2, encode_other.mark002(m, 513, 1, period=4.0))
                 for m in np.arange(t[0] - 2.0, t[-1], 4.0)]
    got = encode_other.blocks(msgs)
    times = [tb for tb, _, _ in got]
    return wrap.pcap(wrap.udp_frames([b for _, _, b in got], 513), times), times


def _read001(data: bytes) -> tuple[np.ndarray, Problems]:
    restorer, problems = cat001.TimeRestorer(), Problems()
    rows = []
    for offset, time, octets in units(data, "pcap", "t", {1, 2}, problems):
        raw = octets[3:]
        if octets[0] == 2:
            cat001.block002(raw, restorer)
        else:
            rows += cat001.block001(raw, offset, time, restorer, problems) or []
    return np.array(rows, dtype=object), problems


@pytest.mark.parametrize("marks", [True, False])
def test_cat001_time_restored_across_midnight(marks: bool) -> None:
    """From CAT002 north marks, or without them from the capture times (the POSIX seconds
    of the pcap, taken modulo a day)."""
    t, slant, bearing = _scene()
    data, _ = _cat001_file(t, slant, bearing, marks=marks)
    rows, problems = _read001(data)
    assert not problems.counts and len(rows) == t.size
    got = rows[:, 0].astype(float)
    err = (got - np.mod(t, 86400.0) + 43200.0) % 86400.0 - 43200.0
    assert np.abs(err).max() <= 1 / 128  # within one LSB of the true time of day
    assert got.min() < 700 and got.max() > 86000  # the file crosses midnight
    assert np.abs(rows[:, 4].astype(float) - slant).max() <= NM / 128
    ang = (rows[:, 5].astype(float) - bearing + 180) % 360 - 180
    assert np.abs(ang).max() <= 360 / 65536


def test_cat001_without_any_reference_counted() -> None:
    t, slant, bearing = _scene(n=5)
    got = encode_other.blocks([(float(t[i]), 513, 1, encode_other.plot001(
        t[i], 513, slant[i], bearing[i])) for i in range(t.size)])
    restorer, problems = cat001.TimeRestorer(), Problems()
    for _, _, b in got:  # a raw stream: no capture time, no CAT002
        assert cat001.block001(b[3:], 0, None, restorer, problems) == []
    assert problems.counts == {"no_time": 5}


def test_cat001_not_plots() -> None:
    t, slant, bearing = _scene(n=60)
    typ = np.arange(60) % 4  # 0 no detection, 1 primary, 2 secondary, 3 combined
    data, _ = _cat001_file(t, slant, bearing, marks=True, typ=typ)
    rows, _ = _read001(data)
    cols = dict(zip(cat001.COLUMNS, rows.T, strict=True))
    keep, counts = real_plots(cols["typ"], cols["sim"], cols["rab"], cols["tst"],
                              track=cols["track"])
    assert counts["no_detection"] == 15 and keep.sum() == 45
    assert np.array_equal(cols["plot_type"].astype(int), typ)


def test_sigma_of_a_95_percent_radius() -> None:
    """σ = R/√(χ²₂(0.95)), the 95 % quantile of a 2-D Gaussian radius, from scipy."""
    k = math.sqrt(chi2.ppf(0.95, 2))
    assert cat021.sigma_m(9, 0, 2) == pytest.approx(30.0 / k, rel=1e-12)
    assert cat021.sigma_m(8, 0, -1) == pytest.approx(0.05 * NM / k, rel=1e-12)
    assert cat021.sigma_m(11, 0, 1) == pytest.approx(3.0 / k, rel=1e-12)
    assert cat021.sigma_m(-1, 7, -1) == pytest.approx(0.05 * NM / k, rel=1e-12)  # NUCp
    assert cat021.sigma_m(3, 9, 0) == pytest.approx(3.0 / k, rel=1e-12)  # VN 0: NUCp
    assert math.isnan(cat021.sigma_m(0, 0, 2)) and math.isnan(cat021.sigma_m(-1, 0, -1))
    # a monotone scale: a higher category is never less accurate
    s = [cat021.sigma_m(n, 0, 2) for n in range(1, 12)]
    assert all(a > b for a, b in itertools.pairwise(s))


def _adsb(n: int = 50) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(8)
    return {"time": np.sort(rng.uniform(0, 86399, n)), "lat": rng.uniform(-89, 89, n),
            "lon": rng.uniform(-179, 179, n), "fl": np.round(rng.uniform(0, 450, n)),
            "nacp": rng.integers(0, 12, n), "tn": rng.integers(0, 4096, n)}


def test_cat021_round_trip_and_pyasteryx() -> None:
    a = _adsb()
    msgs = [(float(a["time"][i]), 0x0102, 21, encode_other.report021(
        a["time"][i], 0x0102, a["lat"][i], a["lon"][i], nacp=int(a["nacp"][i]),
        fl=a["fl"][i], address=f"{i + 0xABC000:06X}", callsign=f"T{i}",
        track_number=int(a["tn"][i]))) for i in range(a["time"].size)]
    blocks = [b for _, _, b in encode_other.blocks(msgs)]
    problems = Problems()
    rows = [r for b in blocks for r in cat021.block021(b[3:], 0, problems) or []]
    assert not problems.counts and len(rows) == a["time"].size
    c = {k: np.array(v) for k, v in zip(cat021.COLUMNS, zip(*rows, strict=True),
                                         strict=True)}
    step = 180.0 / 2**30
    assert np.abs(c["lat"].astype(float) - a["lat"]).max() <= step
    assert np.abs(c["lon"].astype(float) - a["lon"]).max() <= step
    assert np.abs(c["time"].astype(float) - a["time"]).max() <= 1 / 128
    assert np.array_equal(c["flight_level"].astype(float), a["fl"])
    assert c["track_number"].astype(int).tolist() == a["tn"].tolist()
    want = [cat021.sigma_m(int(n), 0, 2) for n in a["nacp"]]
    assert np.allclose(c["sigma"].astype(float), want, equal_nan=True)
    assert set(c["plot_type"].tolist()) == {cat021.ADSB}
    pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx (extra [reference]) "
                                    "not installed")
    ref = [m.items for b in blocks for m in pyasteryx.Decoder().decode(b)]
    assert len(ref) == len(rows)
    assert np.abs(np.array([r["I021/131"]["Lat"] for r in ref]) - c["lat"].astype(float)
                  ).max() <= step
    assert np.abs(np.array([r["I021/131"]["Lon"] for r in ref]) - c["lon"].astype(float)
                  ).max() <= step
    assert [r["I021/090"]["NACp"] for r in ref] == a["nacp"].tolist()
    assert [r["I021/080"]["TAddr"] for r in ref] == c["address"].tolist()
    assert [r["I021/170"]["TId"].strip() for r in ref] == c["callsign"].tolist()
    tod = np.array([r["I021/071"]["time_applicability_position"] for r in ref])
    assert np.array_equal(tod, c["time"].astype(float))


def test_cat021_impossible_values_refused() -> None:
    good = encode_other.report021(100.0, 1, 45.0, 5.0)
    bad_lat = encode_other.report021(100.0, 1, 95.0, 5.0)  # I021/131 holds ±180°
    late = encode_other.report021(100.0, 1, 45.0, 5.0)
    block = encode_other.blocks([(0.0, 1, 21, good), (1.0, 1, 21, bad_lat),
                                 (2.0, 1, 21, late)])[0][2]
    # time of applicability 100 000 s: the 24-bit item holds up to 131 072 s
    block = block.replace((100 * 128).to_bytes(3, "big"), (100000 * 128).to_bytes(3, "big"))
    problems = Problems()
    rows = cat021.block021(block[3:], 0, problems)
    assert rows is not None and len(rows) == 0  # every copy of the time was replaced
    assert problems.counts == {"impossible": 3}
    problems = Problems()
    rows = cat021.block021(encode_other.blocks([(0.0, 1, 21, good), (1.0, 1, 21, bad_lat)]
                                                )[0][2][3:], 0, problems)
    assert rows is not None and len(rows) == 1 and problems.counts == {"impossible": 1}


def test_cat062_reference_refuses_impossible_tracks(tmp_path: Path) -> None:
    step = 180.0 / 2**25

    def msg(i: int, lat: float, tod: int) -> Message:
        return Message(float(i), 0x0709, 62, {
            "010": (("SAC", 7), ("SIC", 9)), "070": tod,
            "105": (("LAT", round(lat / step)), ("LON", round(10.0 / step))),
            "040": i})

    msgs = [msg(0, 45.0, 128), msg(1, 95.0, 256), msg(2, 46.0, 90000 * 128),
            msg(3, 47.0, 512)]
    path = tmp_path / "ref.ast"
    path.write_bytes(b"".join(b for _, _, b in encode_blocks(msgs)))
    cols, problems = read_system_tracks(path)
    assert cols["track_number"].tolist() == [0, 3]
    assert problems.counts == {"impossible": 2}
    assert np.allclose(cols["time"], [1.0, 4.0])


@given(tod=st.floats(0.0, 86399.99), lag=st.floats(-191.9, 191.9))
def test_nearest_tod_recovers_any_time_from_a_reference_within_192_s(tod: float,
                                                                     lag: float) -> None:
    """The property of I001/141: the time of day modulo 512 s, and a reference within
    ±192 s (circularly, across midnight), give the time of day back."""
    ref = (tod + lag) % 86400.0
    got = cat001.nearest_tod(tod % 512.0, ref)
    assert 0.0 <= got < 86400.0
    assert got == pytest.approx(tod, abs=1e-6)


def test_nearest_tod_is_ambiguous_at_192_s_before_midnight() -> None:
    """86 400 = 168 × 512 + 384: the last cycle of the day is 384 s long, so 192 s before
    midnight 86 016 s and 0 s are both 192 s away (the documented limit)."""
    assert 86400 - 168 * 512 == 384
    assert cat001.nearest_tod(0.0, 86400.0 - 150.0) == 0.0
    assert cat001.nearest_tod(0.0, 86400.0 - 250.0) == 86016.0


def test_rows_as_columns_in_the_plot_layout() -> None:
    from mhtrack.io.asterix.columns import columns
    from mhtrack.io.asterix.decode import PLOT_COLUMNS

    assert cat001.COLUMNS[:len(PLOT_COLUMNS)] == PLOT_COLUMNS
    assert cat021.COLUMNS[:len(PLOT_COLUMNS)] == PLOT_COLUMNS
    empty = columns([], cat021.COLUMNS)
    assert all(v.size == 0 for v in empty.values()) and empty["sigma"].dtype == float
    row = encode_other.report021(10.0, 258, 1.0, 2.0, address="ABCDEF")
    cols = columns(cat021.block021(encode_other.blocks([(10.0, 258, 21, row)])[0][2][3:],
                                   0, Problems()) or [], cat021.COLUMNS)
    assert cols["address"].tolist() == ["ABCDEF"] and cols["sensor"].dtype == np.int64
    assert np.isnan(cols["slant_range"][0]) and cols["plot_type"][0] == cat021.ADSB
