"""CAT062 system tracks: a tracks file exported and read back within one LSB, by
libasterix and by pyasteryx (independent)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mhtrack.io.asterix.cat062 import lsb062, read_system_tracks
from mhtrack.io.asterix.cat062_export import export_tracks
from mhtrack.io.sensors import read_sensors


def _tracks(path: Path, n: int = 300, t0: float = 1000.0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(11)
    cols = {"frame": np.arange(n) // 3, "time": t0 + np.arange(n) * 0.7,
            "track_id": rng.integers(0, 65536, n), "lat": rng.uniform(-89, 89, n),
            "lon": rng.uniform(-180, 180, n), "vx": rng.uniform(-600, 600, n),
            "vy": rng.uniform(-600, 600, n),
            "plot": np.where(rng.random(n) < 0.3, -1, rng.integers(0, 999, n)),
            "tentative": (rng.random(n) < 0.2).astype(int)}
    lines = [",".join(cols)] + [",".join(repr(v[i].item()) for v in cols.values())
                                for i in range(n)]
    path.write_text("\n".join(lines).replace(",-1,", ",,") + "\n")  # misses: empty plot
    return cols


@pytest.mark.parametrize("suffix", [".ast", ".pcap"])
def test_round_trip_within_one_lsb(tmp_path: Path, suffix: str) -> None:
    src = _tracks(tmp_path / "tracks.csv")
    n, _ = export_tracks(tmp_path / "tracks.csv", None, tmp_path / f"t{suffix}", sac=7,
                         sic=9)
    assert n == 300
    back, problems = read_system_tracks(tmp_path / f"t{suffix}")
    assert not problems.counts
    L = lsb062()
    assert np.array_equal(back["track_number"], src["track_id"])
    assert np.abs(back["time"] - src["time"]).max() <= L["tod_s"] / 2 + 1e-9
    assert np.abs(back["lat"] - src["lat"]).max() <= L["deg"] / 2 + 1e-12
    assert np.abs(back["lon"] - src["lon"]).max() <= L["deg"] / 2 + 1e-12
    assert np.abs(back["vx"] - src["vx"]).max() <= L["mps"] / 2
    assert np.abs(back["vy"] - src["vy"]).max() <= L["mps"] / 2
    assert np.array_equal(back["tentative"], src["tentative"])
    assert np.array_equal(back["coasting"], (src["plot"] < 0).astype(int))
    assert set(back["sac"].tolist()) == {7} and set(back["sic"].tolist()) == {9}


def test_pyasteryx_reads_the_same(tmp_path: Path) -> None:
    pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx (extra [reference]) "
                                    "not installed")
    src = _tracks(tmp_path / "tracks.csv")
    export_tracks(tmp_path / "tracks.csv", None, tmp_path / "t.pcap")
    ref = [m.items for m in pyasteryx.Decoder().decode_pcap(str(tmp_path / "t.pcap"))]
    assert len(ref) == 300
    L = lsb062()
    assert [r["I062/040"]["TrkN"] for r in ref] == src["track_id"].tolist()
    for key, sub, col, tol in (("I062/105", "Lat", "lat", L["deg"]),
                               ("I062/105", "Lon", "lon", L["deg"]),
                               ("I062/185", "Vx", "vx", L["mps"]),
                               ("I062/185", "Vy", "vy", L["mps"]),
                               ("I062/070", "ToT", "time", L["tod_s"])):
        got = np.array([r[key][sub] for r in ref])
        assert np.abs(got - src[col]).max() <= tol, col
    assert [r["I062/080"]["CNF"] for r in ref] == src["tentative"].tolist()
    assert [r["I062/080"]["CST"] for r in ref] == (src["plot"] < 0).astype(int).tolist()


def test_local_tracks_through_the_sensors_frame(opensky: Path, tmp_path: Path) -> None:
    sensors = read_sensors(opensky / "sensors.toml")
    x, y = np.array([0.0, 1e5, -5e4]), np.array([0.0, 2e4, 8e4])
    (tmp_path / "local.csv").write_text("time,track_id,x,y,vx,vy\n" + "".join(
        f"{i},{i},{x[i]},{y[i]},100,0\n" for i in range(3)))
    export_tracks(tmp_path / "local.csv", sensors, tmp_path / "l.ast")
    back, _ = read_system_tracks(tmp_path / "l.ast")
    lat, lon = sensors.frame().to_geodetic(x, y)
    assert np.abs(back["lat"] - lat).max() <= lsb062()["deg"]
    assert np.abs(back["lon"] - lon).max() <= lsb062()["deg"]
    # a grid velocity of 100 m/s east is about 100 m/s east on the ground near the origin
    assert np.abs(back["vx"] - 100.0).max() < 2.0 and np.abs(back["vy"]).max() < 3.0


def test_raw_reference_with_a_damaged_length(tmp_path: Path) -> None:
    """A raw CAT062 file (a reference for ``evaluate --reference``) whose block 3 has
    its length made to cover blocks 4 and 5 exactly: read as ``convert`` reads a raw
    stream (blocks judged by their content), every other block's tracks are kept, block
    3 counted as damage; by framing alone blocks 4 and 5 went with it."""
    _tracks(tmp_path / "tracks.csv")
    export_tracks(tmp_path / "tracks.csv", None, tmp_path / "t.ast")
    data = bytearray((tmp_path / "t.ast").read_bytes())
    starts = [0]
    while starts[-1] < len(data):
        starts.append(starts[-1] + int.from_bytes(data[starts[-1] + 1:starts[-1] + 3], "big"))
    assert len(starts) > 8 and starts[-1] == len(data)
    (tmp_path / "b3.ast").write_bytes(bytes(data[starts[3]:starts[4]]))
    data[starts[3] + 1:starts[3] + 3] = (starts[6] - starts[3]).to_bytes(2, "big")
    (tmp_path / "d.ast").write_bytes(bytes(data))

    def keys(path: Path) -> list[tuple[int, float]]:
        cols, _ = read_system_tracks(path)
        return sorted(zip(cols["track_number"].tolist(), cols["time"].tolist(), strict=True))

    whole, lost = keys(tmp_path / "t.ast"), keys(tmp_path / "b3.ast")
    got, problems = keys(tmp_path / "d.ast"), read_system_tracks(tmp_path / "d.ast")[1]
    assert got == sorted(set(whole) - set(lost)) and len(got) == len(whole) - len(lost)
    assert problems.counts == {"resync": 1, "skipped_octets": starts[4] - starts[3]}
    assert problems.first["resync"] == starts[3]
