"""``mhtrack convert``, ``export`` and ``track RECORDING`` end to end."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow.csv as pacsv
import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli

pytest.importorskip("asterix.generated", reason="libasterix not installed "
                    "(pip install 'mhtrack[asterix]')")


def _run(*args: object) -> object:
    return CliRunner().invoke(cli, [str(a) for a in args])


@pytest.fixture(scope="module")
def sim(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """opensky-radars plots (positions only: ``--no-attributes``) cut to their first 2 000
    rows, with sensors.toml and truth."""
    out = tmp_path_factory.mktemp("sim")
    r = _run("simulate", "opensky-radars", "--seed", "1", "--no-attributes", "--out", out)
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    lines = (out / "plots.csv").read_text().splitlines()[:2001]
    (out / "plots.csv").write_text("\n".join(lines) + "\n")
    return out


def test_export_convert(sim: Path, tmp_path: Path) -> None:
    rec = tmp_path / "rec.pcap"
    r = _run("export", sim / "plots.csv", "--sensors", sim / "sensors.toml", "--out", rec)
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    assert "2000 plots in" in r.output  # type: ignore[attr-defined]
    out = tmp_path / "plots.csv"
    r = _run("convert", rec, "--out", out, "--sensors", sim / "sensors.toml")
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    assert r.output.startswith("pcap recording: 2000 plots")  # type: ignore[attr-defined]
    t = pacsv.read_csv(out)
    assert t.column_names == ["time", "sensor", "sac", "sic", "slant_range", "bearing",
                              "flight_level", "mode_3a", "address", "callsign",
                              "track_number", "typ", "plot_type", "range"]
    assert t.num_rows == 2000


def test_convert_output_spellings(sim: Path, tmp_path: Path) -> None:
    """``-o``, ``--out`` and the older positional OUTPUT write the same plots file; none
    or two of them is a usage error that names --out (issue 31, one vocabulary)."""
    rec = tmp_path / "rec.ast"
    assert _run("export", sim / "plots.csv", "--sensors", sim / "sensors.toml", "--out",
                rec).exit_code == 0  # type: ignore[attr-defined]
    outs = [tmp_path / f"{k}.csv" for k in "abc"]
    for args in (["-o", outs[0]], ["--out", outs[1]], [outs[2]]):
        r = _run("convert", rec, *args)
        assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    assert outs[0].read_bytes() == outs[1].read_bytes() == outs[2].read_bytes()
    for args in ([], [tmp_path / "d.csv", "--out", tmp_path / "e.csv"]):
        r = _run("convert", rec, *args)
        assert r.exit_code == 2
        assert "--out FILE" in r.output  # type: ignore[attr-defined]
    assert not (tmp_path / "d.csv").exists() and not (tmp_path / "e.csv").exists()


def test_export_refuses_other_extensions(sim: Path, tmp_path: Path) -> None:
    r = _run("export", sim / "plots.csv", "--sensors", sim / "sensors.toml", "--out",
             tmp_path / "rec.csv")
    assert r.exit_code == 2
    assert "expected .pcap, .ast" in r.output  # type: ignore[attr-defined]


def test_track_recording(sim: Path, tmp_path: Path) -> None:
    rec = tmp_path / "rec.ast"
    assert _run("export", sim / "plots.csv", "--sensors", sim / "sensors.toml", "--out",
                rec).exit_code == 0  # type: ignore[attr-defined]
    a, b = tmp_path / "from_plots.csv", tmp_path / "from_rec.csv"
    r1 = _run("track", sim / "plots.csv", "--sensors", sim / "sensors.toml", "--out", a,
              "--no-progress")
    r2 = _run("track", rec, "--sensors", sim / "sensors.toml", "--out", b, "--no-progress")
    assert r1.exit_code == 0 and r2.exit_code == 0, r2.output  # type: ignore[attr-defined]
    ta, tb = pacsv.read_csv(a), pacsv.read_csv(b)
    # the same targets tracked: same number of frames, track positions within metres
    assert set(tb.column_names) >= {"time", "track_id", "lat", "lon"}
    last_a = ta.column("time").to_numpy().max()
    last_b = tb.column("time").to_numpy().max()
    assert abs(last_a - last_b) < 0.01
    n_a = len(set(ta.column("track_id").to_pylist()))
    n_b = len(set(tb.column("track_id").to_pylist()))
    assert abs(n_a - n_b) <= max(2, n_a // 10)
    assert not list(tmp_path.glob("mhtrack-asterix-*"))


def test_track_recording_needs_sensors(sim: Path, tmp_path: Path) -> None:
    rec = tmp_path / "rec.ast"
    _run("export", sim / "plots.csv", "--sensors", sim / "sensors.toml", "--out", rec)
    r = _run("track", rec, "--out", tmp_path / "t.csv")
    assert r.exit_code == 2
    assert "is an ASTERIX recording: give its radars with --sensors" in r.output  # type: ignore[attr-defined]


def test_track_recording_unknown_radar(sim: Path, tmp_path: Path,
                                      caplog: pytest.LogCaptureFixture) -> None:
    """A radar of the recording that the sensors file does not list (and whose CAT034
    gives no site) is skipped with one warning line naming it; the others are tracked."""
    rec = tmp_path / "rec.ast"
    _run("export", sim / "plots.csv", "--sensors", sim / "sensors.toml", "--out", rec)
    text = (sim / "sensors.toml").read_text().replace("id = 3", "id = 7")
    (tmp_path / "s.toml").write_text(text)
    with caplog.at_level("WARNING", logger="mhtrack"):
        r = _run("track", rec, "--sensors", tmp_path / "s.toml", "--out", tmp_path / "t.csv")
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    lines = [m.getMessage() for m in caplog.records if "skipped" in m.getMessage()]
    assert len(lines) == 1 and "1 radar(s) without a known site skipped" in lines[0]
    assert "rec.ast" in lines[0] and "3 (SAC 0, SIC 3)" in lines[0], lines[0]
    assert (tmp_path / "t.csv").exists()


def test_random_bytes_one_line(tmp_path: Path) -> None:
    path = tmp_path / "noise.ast"
    path.write_bytes(b"\x00" + np.random.default_rng(1).bytes(999))
    r = _run("convert", path, tmp_path / "p.csv")
    assert r.exit_code == 2
    assert "noise.ast: byte 0: not an ASTERIX recording" in r.output  # type: ignore[attr-defined]
    assert len(r.output.strip().splitlines()) == 1  # type: ignore[attr-defined]


def test_missing_libasterix(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from mhtrack.io.asterix import _lib

    def missing() -> None:
        raise _lib.MissingExtra(_lib.INSTALL_HINT)

    monkeypatch.setattr(_lib, "modules", missing)
    path = tmp_path / "x.ast"
    path.write_bytes(bytes([48, 0, 3]))
    r = _run("convert", path, tmp_path / "p.csv")
    assert r.exit_code == 1
    assert r.output.strip() == "Error: " + _lib.INSTALL_HINT  # type: ignore[attr-defined]


def test_export_tracks_as_cat062(sim: Path, tmp_path: Path) -> None:
    from mhtrack.io.asterix.cat062 import read_system_tracks

    tracks = tmp_path / "tracks.csv"
    tracks.write_text("frame,time,track_id,lat,lon,vx,vy,plot,tentative\n"
                      "1,10.0,5,52.1,-1.2,200,10,3,1\n2,14.0,5,52.11,-1.19,201,9,,0\n")
    out = tmp_path / "system.pcap"
    r = _run("export", tracks, "--out", out, "--category", "062", "--sac", 25, "--sic", 200)
    assert r.exit_code == 0, r.output  # type: ignore[attr-defined]
    assert "2 track updates in" in r.output  # type: ignore[attr-defined]
    back, _ = read_system_tracks(out)
    assert back["track_number"].tolist() == [5, 5]
    assert back["tentative"].tolist() == [1, 0] and back["coasting"].tolist() == [0, 1]
    assert back["sic"].tolist() == [200, 200]
    r = _run("export", sim / "plots.csv", "--out", tmp_path / "p.ast")
    assert r.exit_code == 2
    assert "needs --sensors FILE" in r.output  # type: ignore[attr-defined]
