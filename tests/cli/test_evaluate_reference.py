"""``mhtrack evaluate TRACKS --reference REC``: our tracks scored against a reference
system's CAT062 tracks (issue 28, deliverable 2), end to end."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli

pytest.importorskip("asterix.generated", reason="libasterix not installed "
                    "(pip install 'mhtrack[asterix]')")


def _run(*args: object) -> object:
    return CliRunner().invoke(cli, [str(a) for a in args])


def test_tracker_output_as_its_own_reference(tmp_path: Path) -> None:
    """opensky-radars (12 scans) tracked, the tracks exported as CAT062 and taken as the
    reference: every reference track is one of ours, no false track, no switch; the
    only possible misses are at a track's ends, where I062/070 rounds its first or last
    time by up to 1/256 s."""
    r = _run("simulate", "opensky-radars", "--seed", "1", "--scans", 12, "--out", tmp_path)
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    tracks = tmp_path / "tracks.csv"
    r = _run("track", tmp_path / "plots.csv", "--out", tracks)
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    rec = tmp_path / "ref.pcap"
    r = _run("export", tracks, "--category", "062", "--out", rec, "--sensors",
             tmp_path / "sensors.toml")
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    r = _run("evaluate", tracks, "--reference", rec, "--json")
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    out = json.loads(r.stdout)  # type: ignore[attr-defined]
    n_ids = len(set(np.loadtxt(tracks, delimiter=",", skiprows=1, usecols=2).tolist()))
    assert out["n_targets"] == out["n_tracks"] == n_ids
    assert out["n_false"] == 0 and out["id_switches"] == 0
    assert out["n_misses"] <= 2 * n_ids and out["coverage"] >= 0.99
    assert out["motp"] < 1.0  # metres: the I062/105 LSB is 0.6 m
    assert "reference tracks, sampled every" in r.stderr  # type: ignore[attr-defined]


def _message(i: int, lat: float, tod_s: float) -> object:
    from mhtrack.io.asterix.encode import Message

    step = 180.0 / 2**25
    return Message(tod_s, 0x0709, 62, {
        "010": (("SAC", 7), ("SIC", 9)), "070": round(tod_s * 128),
        "105": (("LAT", round(lat / step)), ("LON", round(11.0 / step))),
        "185": (("VX", 0), ("VY", 0)), "040": i})


def test_impossible_reference_records_refused_with_one_line(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """A reference with a latitude of 95° and a time of day of 90 000 s among good
    records: both refused, counted in one warning line naming the file and the byte of
    the first (checked against pyasteryx, an independent decoder, which reads the 95°
    there), and never scored — our tracks equal to the good records match them all."""
    from mhtrack.io.asterix.encode import encode_blocks

    good = [_message(k, 48.0 + 0.001 * t, 1000.0 + 4 * t) for k in (1, 2)
            for t in range(6)]
    bad = [_message(3, 95.0, 1010.0), _message(4, 48.5, 90000.0)]
    blocks = [b for m in good[:5] + bad[:1] + good[5:] + bad[1:]
              for _, _, b in encode_blocks([m])]  # type: ignore[list-item]
    rec = tmp_path / "ref.ast"
    rec.write_bytes(b"".join(blocks))
    first_bad = sum(len(b) for b in blocks[:5])
    tracks = tmp_path / "tracks.csv"
    tracks.write_text("frame,time,track_id,lat,lon,vx,vy,plot\n" + "".join(
        f"{j},{m.time},{m.items['040']},{m.items['105'][0][1] * 180 / 2**25},11.0,0,0,\n"
        for j, m in enumerate(sorted(good, key=lambda m: m.time))))  # type: ignore[attr-defined]
    with caplog.at_level("WARNING", logger="mhtrack"):
        r = _run("evaluate", tracks, "--reference", rec, "--json")
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    lines = [m.getMessage() for m in caplog.records if m.levelname == "WARNING"]
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"{rec}: 2 report(s) with a physically impossible value")
    assert f"(first at byte {first_bad};" in lines[0], lines[0]
    out = json.loads(r.stdout)  # type: ignore[attr-defined]
    assert out["n_targets"] == 2 and out["n_misses"] == 0 and out["n_false"] == 0
    pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx not installed")
    there = [m.items for m in pyasteryx.Decoder().decode(rec.read_bytes()[first_bad:])]
    assert there[0]["I062/105"]["Lat"] == pytest.approx(95.0, abs=1e-5)
    assert there[-1]["I062/070"]["ToT"] == pytest.approx(90000.0)


def test_truth_or_reference_not_both(tmp_path: Path) -> None:
    (tmp_path / "t.csv").write_text("scan,time,track_id,x,y,vx,vy,plot\n")
    r = _run("evaluate", tmp_path / "t.csv")
    assert r.exit_code == 2 and "give TRUTH or --reference REC" in r.output  # type: ignore[attr-defined]
    r = _run("evaluate", tmp_path / "t.csv", tmp_path / "t.csv", "--reference",
             tmp_path / "t.csv")
    assert r.exit_code == 2 and "give TRUTH or --reference REC" in r.output  # type: ignore[attr-defined]
    r = _run("evaluate", tmp_path / "t.csv", "--reference", tmp_path / "t.csv", "--plots",
             tmp_path / "t.csv")
    assert r.exit_code == 2 and "apply to TRUTH only" in r.output  # type: ignore[attr-defined]


def test_reference_that_cannot_be_sampled_one_line(tmp_path: Path) -> None:
    """A single update gives no update period: one line naming the file, until the
    period is given."""
    from mhtrack.io.asterix.encode import encode_blocks

    rec = tmp_path / "one.ast"
    rec.write_bytes(b"".join(b for _, _, b in encode_blocks([_message(1, 48.0, 1000.0)])))  # type: ignore[list-item]
    tracks = tmp_path / "t.csv"
    tracks.write_text("frame,time,track_id,lat,lon,vx,vy,plot\n0,1000.0,1,48.0,11.0,0,0,\n")
    r = _run("evaluate", tracks, "--reference", rec)
    assert r.exit_code == 2, r.output  # type: ignore[attr-defined]
    assert r.output.strip().splitlines() == [  # type: ignore[attr-defined]
        f"Error: {rec}: no reference track has two updates at different times: give the "
        "reference's update period (--reference-period S)"]
    r = _run("evaluate", tracks, "--reference", rec, "--reference-period", 4, "--json")
    assert r.exit_code == 0 and json.loads(r.stdout)["n_matches"] == 1  # type: ignore[attr-defined]
