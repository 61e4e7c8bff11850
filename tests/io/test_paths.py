"""Output paths are checked before any work; an output never overwrites an input."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli
from mhtrack.errors import InputError
from mhtrack.io.paths import check_output_dir, check_output_file
from mhtrack.pipeline import run as pipeline_run


def test_check_output_file(tmp_path: Path) -> None:
    src = tmp_path / "p.csv"
    src.write_text("x\n")
    with pytest.raises(InputError, match="is the input file"):
        check_output_file(tmp_path / "." / "p.csv", inputs=(src,))
    with pytest.raises(InputError, match=r"unknown extension '\.txt'"):
        check_output_file(tmp_path / "t.txt")
    with pytest.raises(InputError, match="does not exist"):
        check_output_file(tmp_path / "missing" / "t.csv")
    with pytest.raises(InputError, match="is a folder"):
        (tmp_path / "d.csv").mkdir()
        check_output_file(tmp_path / "d.csv")
    check_output_file(tmp_path / "t.parquet", inputs=(src, None))  # fine


def test_check_output_dir(tmp_path: Path) -> None:
    f = tmp_path / "f"
    f.write_text("")
    with pytest.raises(InputError, match="is a file"):
        check_output_dir(f)
    check_output_dir(tmp_path / "new" / "deeper")  # created later by the writers


def test_track_refuses_its_input_as_output_before_any_work(tmp_path, monkeypatch) -> None:
    runner = CliRunner()
    out = tmp_path / "sim"
    assert runner.invoke(cli, ["simulate", "crossing", "--seed", "1", "--scans", "5",
                               "--out", str(out)]).exit_code == 0
    plots = out / "plots.csv"
    before = plots.read_bytes()

    def never(*a, **k):  # the tracker must not run
        raise AssertionError("tracked although the output is the input")

    monkeypatch.setattr(pipeline_run, "step_frames", never)
    res = runner.invoke(cli, ["track", str(plots), "--out", str(plots), "--no-progress"])
    assert res.exit_code != 0 and "is the input file" in res.output
    assert plots.read_bytes() == before
    res = runner.invoke(cli, ["track", str(plots), "--out", str(tmp_path / "no" / "t.csv"),
                              "--no-progress"])
    assert res.exit_code != 0 and "does not exist" in res.output
