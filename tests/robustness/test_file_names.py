"""File names that are any byte string the OS accepts (issue 33): names that are not
UTF-8 reach Python as surrogate escapes (PEP 383); every reader and writer takes them,
and every message prints them safely as ``\\xNN`` (before: pyarrow's "'utf-8' codec can't
encode characters … surrogates not allowed")."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli
from mhtrack.errors import InputError, printable

#: A folder and file names with bytes that are not UTF-8 (0xff, 0xfe), and valid UTF-8.
ODD = os.fsdecode(b"d\xff\xfe-\xc3\xa9")


def _run(args: list[str]) -> tuple[int, str]:
    res = CliRunner().invoke(cli, args)
    assert "Traceback" not in res.output and not isinstance(
        res.exception, UnicodeError), (res.output, res.exception)
    return res.exit_code, res.output


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_simulate_track_evaluate_in_a_folder_that_is_not_utf8(tmp_path: Path,
                                                              fmt: str) -> None:
    out = tmp_path / ODD
    code, text = _run(["simulate", "crossing", "--scans", "4", "--out", str(out),
                       "--format", fmt])
    assert code == 0, text
    tracks = out / os.fsdecode(b"tracks-\xff.csv")
    code, text = _run(["track", str(out / f"plots.{fmt}"), "--out", str(tracks)])
    assert code == 0, text
    assert tracks.exists() and tracks.read_text().startswith("scan,")
    assert os.fsencode(tracks.name) == b"tracks-\xff.csv"
    code, text = _run(["evaluate", str(tracks), str(out / f"truth.{fmt}")])
    assert code == 0, text


def test_a_refusal_names_the_file_printably(tmp_path: Path) -> None:
    """An error about such a file: exit 2, one line, the odd bytes shown as \\xff\\xfe."""
    out = tmp_path / ODD
    out.mkdir()
    bad = out / "plots.csv"
    bad.write_text("scan,time,sensor,x,y\n0,0,0,1,nan\n")
    code, text = _run(["track", str(bad), "--out", str(out / "t.csv")])
    assert code == 2
    assert "d\\xff\\xfe-é/plots.csv, line 2, column 'y'" in text, text


def test_input_error_messages_are_printable() -> None:
    e = InputError(f"{ODD}/x.csv: bad")
    assert str(e) == "d\\xff\\xfe-é/x.csv: bad"
    str(e).encode("utf-8")  # never a codec error
    assert printable(b"a\xffb") == "a\\xffb"


def test_state_and_sensors_files_with_odd_names(tmp_path: Path) -> None:
    from mhtrack.clutter.known import KnownClutter
    from mhtrack.io.sensors import read_sensors, write_sensors
    from mhtrack.mht import MHTConfig, MHTTracker
    from mhtrack.models.radars import RadarSensor, SensorSet

    folder = tmp_path / ODD
    folder.mkdir()
    trk = MHTTracker(MHTConfig(), KnownClutter(1e-8))
    trk.save(folder / os.fsdecode(b"s\xff.npz"))
    assert MHTTracker.load(folder / os.fsdecode(b"s\xff.npz")).config == trk.config
    s = SensorSet((46.8, 8.2), (RadarSensor(1, "cartesian", sigma=5.0, pd=0.9),))
    write_sensors(s, folder / os.fsdecode(b"r\xff.toml"))
    assert read_sensors(folder / os.fsdecode(b"r\xff.toml")) == s


def test_run_report_montecarlo_and_study_page_in_odd_folders(tmp_path: Path) -> None:
    """The report pages print the folder's name: before, atomic_write's UTF-8 encoding
    failed on it ('surrogates not allowed') after all the work."""
    pytest.importorskip("plotly", reason="the HTML report needs the extra [report]")
    run = tmp_path / ODD / "run"
    code, text = _run(["run", "crossing", "--scans", "4", "--out", str(run), "--report"])
    assert code == 0, text
    page = (run / "report.html").read_bytes()
    page.decode("utf-8")  # valid UTF-8, the odd bytes shown as \xff\xfe
    study = tmp_path / ODD / os.fsdecode(b"mc\xff")
    code, text = _run(["montecarlo", "crossing", "--runs", "2", "--scans", "4", "--out",
                       str(study)])
    assert code == 0, text
    code, text = _run(["report", str(study)])
    assert code == 0, text
    (study / "report.html").read_bytes().decode("utf-8")


def test_asterix_export_and_convert_with_odd_names(tmp_path: Path) -> None:
    pytest.importorskip("asterix")
    sim = tmp_path / ODD
    code, text = _run(["simulate", "opensky-radars", "--out", str(sim)])
    assert code == 0, text
    rec = sim / os.fsdecode(b"rec\xff.pcap")
    code, text = _run(["export", str(sim / "plots.csv"), "--sensors",
                       str(sim / "sensors.toml"), "--out", str(rec)])
    assert code == 0, text
    conv = sim / os.fsdecode(b"conv\xfe.csv")
    code, text = _run(["convert", str(rec), str(conv), "--sensors",
                       str(sim / "sensors.toml")])
    assert code == 0, text
    assert conv.read_text().count("\n") > 1000
