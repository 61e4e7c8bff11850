"""One vocabulary on every command (issue 31): ``-v``/``--log-file`` everywhere, other
libraries' loggers kept at WARNING under ``-vv``, ``-o`` as the short form of ``--out``,
the former ``--output`` spelling of ``plot``/``report`` kept as a hidden alias, and
``--dask-scheduler`` without Dask one line naming the extra."""

from __future__ import annotations

import logging
import sys

import click
import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli


def _commands(group=cli, prefix=()):
    for name, cmd in sorted(group.commands.items()):
        if isinstance(cmd, click.Group):
            yield from _commands(cmd, (*prefix, name))
        else:
            yield (*prefix, name), cmd


@pytest.mark.parametrize(("path", "cmd"), list(_commands()), ids=lambda v: "-".join(v)
                         if isinstance(v, tuple) else "")
def test_every_command_has_the_vocabulary(path, cmd):
    opts = {o for p in cmd.params for o in p.opts}
    assert {"-v", "--verbose", "--log-file", "-q", "--quiet", "--progress"} <= opts, path
    if "--out" in opts:
        assert "-o" in opts, path


@pytest.fixture
def crossing(tmp_path):
    r = CliRunner().invoke(cli, ["simulate", "crossing", "--scans", "8", "-o",
                                 str(tmp_path / "c")])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, ["track", str(tmp_path / "c" / "plots.csv"), "-o",
                                 str(tmp_path / "c" / "tracks.csv"), "--quiet"])
    assert r.exit_code == 0, r.output
    return tmp_path / "c"


def test_vv_keeps_other_libraries_quiet_and_log_file_gets_mhtracks_lines(crossing, tmp_path):
    log = tmp_path / "run.log"
    r = CliRunner().invoke(cli, ["-vv", "evaluate", str(crossing / "tracks.csv"),
                                 str(crossing / "truth.csv"), "--log-file", str(log)])
    assert r.exit_code == 0, r.output
    # a third-party logger's DEBUG line (as matplotlib's font manager logs) stays out
    logging.getLogger("matplotlib.font_manager").debug("findfont: score(...)")
    logging.getLogger("mhtrack.test").debug("own debug line")
    assert logging.getLogger("matplotlib").getEffectiveLevel() == logging.WARNING
    assert logging.getLogger("mhtrack").getEffectiveLevel() == logging.DEBUG
    text = log.read_text()
    assert "mhtrack.metrics INFO: evaluated" in text          # the summary, at INFO
    assert "mhtrack.progress DEBUG: evaluate: OSPA in" in text  # per stage, at DEBUG
    assert "own debug line" in text and "findfont" not in text
    assert "mhtrack: DEBUG: evaluate: OSPA in" in r.stderr   # and on stderr with -vv


def test_without_v_only_warnings_on_stderr_but_the_file_gets_info(crossing, tmp_path):
    log = tmp_path / "quiet.log"
    r = CliRunner().invoke(cli, ["evaluate", str(crossing / "tracks.csv"),
                                 str(crossing / "truth.csv"), "--log-file", str(log)])
    assert r.exit_code == 0, r.output
    assert "INFO" not in r.stderr and "DEBUG" not in r.stderr
    text = log.read_text()
    assert "INFO: evaluated" in text and "DEBUG" not in text


def test_matplotlib_debug_never_reaches_stderr_with_vv(crossing):
    """``plot -vv`` draws with matplotlib (which logs its font search at DEBUG)."""
    r = CliRunner().invoke(cli, ["-vv", "plot", str(crossing), "-o",
                                 str(crossing / "s.png")])
    assert r.exit_code == 0, r.output
    assert "matplotlib" not in r.stderr and "findfont" not in r.stderr


def test_plot_out_and_the_hidden_output_alias(crossing):
    for opt, name in (("--out", "a.png"), ("-o", "b.png"), ("--output", "c.png")):
        r = CliRunner().invoke(cli, ["plot", str(crossing), opt, str(crossing / name)])
        assert r.exit_code == 0, r.output
        assert (crossing / name).is_file()
    assert "--output" not in CliRunner().invoke(cli, ["plot", "--help"]).output


def test_evaluate_out_writes_what_stdout_shows(crossing):
    args = ["evaluate", str(crossing / "tracks.csv"), str(crossing / "truth.csv"), "--json"]
    shown = CliRunner().invoke(cli, args).stdout
    r = CliRunner().invoke(cli, [*args, "-o", str(crossing / "m.json")])
    assert r.exit_code == 0, r.output
    assert (crossing / "m.json").read_text() == shown


def test_dask_scheduler_without_dask_is_one_line(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed fails
    r = CliRunner().invoke(cli, ["montecarlo", "crossing", "--trackers", "mht", "--runs",
                                 "1", "--dask-scheduler", "tcp://127.0.0.1:9", "--out",
                                 str(tmp_path / "mc")])
    assert r.exit_code == 1
    assert r.stderr.strip().splitlines() == [
        "Error: --dask-scheduler needs Dask's distributed scheduler: "
        "pip install 'mhtrack[dask]'"]


def test_simulate_logs_per_scan_at_debug_and_a_summary_at_info(tmp_path):
    r = CliRunner().invoke(cli, ["simulate", "crossing", "--scans", "3", "-vv", "-o",
                                 str(tmp_path / "s")])
    assert r.exit_code == 0, r.output
    lines = r.stderr.splitlines()
    per_scan = [ln for ln in lines if ln.startswith("mhtrack: DEBUG: simulate: scan ")]
    assert len(per_scan) == 3  # one scan, one sensor each
    assert [ln for ln in lines if ln.startswith("mhtrack: INFO: simulate crossing")]
    r = CliRunner().invoke(cli, ["simulate", "crossing", "--scans", "3", "-v", "-o",
                                 str(tmp_path / "t")])
    assert "DEBUG" not in r.stderr and "INFO: simulate crossing" in r.stderr


def test_evaluate_and_report_progress_bar_only_when_asked_or_on_a_terminal(crossing):
    pytest.importorskip("plotly", reason="report needs the extra [report]")
    ev = ["evaluate", str(crossing / "tracks.csv"), str(crossing / "truth.csv")]
    rep = ["report", str(crossing), "-o", str(crossing / "r.html")]
    for args, last in ((ev, "HOTA"), (rep, "render")):
        shown = CliRunner().invoke(cli, [*args, "--progress"])
        assert shown.exit_code == 0, shown.output
        assert f"{args[0]}:" in shown.stderr and last in shown.stderr  # the bar, its stages
        for quiet in ([], ["--quiet"]):  # CliRunner's stderr is no terminal: no bar
            r = CliRunner().invoke(cli, [*args, *quiet])
            assert r.exit_code == 0 and r.stderr == "", r.stderr
