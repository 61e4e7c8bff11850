"""Times of day moved on (:mod:`mhtrack.io.asterix.retime`, ``replay --loop``): CAT001 and
CAT002 octets built by hand and moved by hand; an exported CAT048/CAT034 recording
decoded before and after (every time + s modulo the day, every other column the same);
CAT021 against libasterix's own ``set_item``; a whole day changes nothing."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.io.asterix import encode_other
from mhtrack.io.asterix.decode import Decoder, read_recording
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.retime import patch_times, shift_times, time_fields
from mhtrack.io.asterix.timeaxis import DAY_S
from mhtrack.sources.replay import recording_datagrams


def _cat001(tod: int) -> bytes:
    """A CAT002 north marker then a CAT001 plot (layouts of test_categories.py), both at
    ``tod`` s; the plot's time truncated to 16 bits."""
    cat2 = bytes([0b11010000, 7, 9, 1]) + (tod * 128 % (86400 * 128)).to_bytes(3, "big")
    plot = bytes([0b11111010, 7, 9, 0b00110001, 0b10000000]) + struct.pack(
        "!HHHHH", 12800, 16384, 0o7700, 1400, tod * 128 % 65536)
    return (bytes([2]) + (3 + len(cat2)).to_bytes(2, "big") + cat2
            + bytes([1]) + (3 + len(plot)).to_bytes(2, "big") + plot)


def test_cat001_and_cat002_by_hand() -> None:
    payload = _cat001(86_390)
    # CAT002: header 3, FSPEC 1, I002/010 2, 000 1 → 030 at 7; CAT001 at 10: header 3,
    # FSPEC 1, I001/010 2, 020 2, 040 4, 070 2, 090 2 → 141 at 26
    assert time_fields(payload) == ((7, 3, 86400 * 128), (26, 2, 65536))
    # 86 390 s + 25 s = 15 s of the next day: both items as if built at 15 s
    assert shift_times(payload, 25, near=86_395.0) == _cat001(15)
    assert shift_times(payload, 0) == payload
    with pytest.raises(ValueError, match="truncated"):
        shift_times(payload, 25)


@pytest.fixture(scope="module")
def exported(opensky_head: Path, opensky: Path, tmp_path_factory: pytest.TempPathFactory
             ) -> Path:
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    out = tmp_path_factory.mktemp("retime") / "r.ast"
    r = CliRunner().invoke(cli, ["export", str(opensky_head), "--sensors",
                                 str(opensky / "sensors.toml"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    return out


def test_cat048_cat034_decoded_before_and_after(exported: Path, tmp_path: Path) -> None:
    payloads = [p for p, _ in recording_datagrams(exported)][:300]
    before = tmp_path / "a.ast"
    before.write_bytes(b"".join(payloads))
    s = 86_400 - 7_000  # crosses midnight for every time after 7 000 s
    after = tmp_path / "b.ast"
    after.write_bytes(b"".join(shift_times(p, s) for p in payloads))
    a, b = read_recording(before), read_recording(after)
    tod_a = np.mod(a.plots["time"], DAY_S)
    assert np.array_equal(np.mod(b.plots["time"], DAY_S), np.mod(tod_a + s, DAY_S))
    assert np.array_equal(np.mod(b.sweeps["time"], DAY_S),
                          np.mod(np.mod(a.sweeps["time"], DAY_S) + s, DAY_S))
    for name in a.plots:
        if name != "time":
            floats = a.plots[name].dtype.kind == "f"
            assert np.array_equal(a.plots[name], b.plots[name], equal_nan=floats), name
    assert [len(shift_times(p, s)) for p in payloads] == [len(p) for p in payloads]


def test_cat021_as_libasterix_sets_it() -> None:
    recs = [encode_other.report021(t, 0x0102, 50.0, 8.0) for t in (86_399.5, 100.25)]
    (_, _, block), = encode_other.blocks([(100.0, 0x0102, 21, r) for r in recs])
    s = 3
    want = []
    for r in recs:
        for name in ("071", "072", "073", "075", "077"):
            item = r.get_item(name)
            if item is not None:
                raw = int(item.variation.content.as_uint())
                r = r.set_item(name, (raw + 128 * s) % (86400 * 128))
        want.append(r)
    (_, _, expected), = encode_other.blocks([(100.0, 0x0102, 21, r) for r in want])
    assert time_fields(block), "no time item found"
    assert shift_times(block, s) == expected
    rows = [r for _, _, r in Decoder().blocks(shift_times(block, s), 0, Problems())]
    assert [row[0] for row in rows[0]] == [2.5, 103.25]


@settings(max_examples=25, deadline=None)
@given(seconds=st.integers(1, 3 * 86_400), tod=st.integers(0, 86_399))
def test_moves_add_up_and_a_day_is_nothing(seconds: int, tod: int) -> None:
    payload = _cat001(tod)
    fields = time_fields(payload)
    once = patch_times(payload, fields, seconds, near=tod + 100.0)
    later = (tod + seconds) % 86_400
    assert once == _cat001(later)
    assert patch_times(once, fields, 2 * 86_400 - seconds, near=later - 100.0) == payload
    with pytest.raises(ValueError, match="whole number"):
        patch_times(payload, fields, 0.5)  # type: ignore[arg-type]
