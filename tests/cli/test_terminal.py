"""The progress bar is drawn only on a terminal unless --progress / --quiet say otherwise."""

import io

import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli
from mhtrack.cli.terminal import progress_enabled, rerun_command


class Tty(io.StringIO):
    def isatty(self):
        return True


def test_progress_enabled_follows_the_terminal_unless_chosen():
    assert progress_enabled(None, Tty()) is True
    assert progress_enabled(None, io.StringIO()) is False
    assert progress_enabled(True, io.StringIO()) is True
    assert progress_enabled(False, Tty()) is False
    closed = io.StringIO()
    closed.close()
    assert progress_enabled(None, closed) is False


def test_rerun_command_is_shell_quoted():
    assert rerun_command(["montecarlo", "crossing", "--out", "my dir"]) == (
        "mhtrack montecarlo crossing --out 'my dir'")


def bar_written(stderr: str) -> bool:
    return "%|" in stderr or "it/s" in stderr or "scan/s" in stderr


@pytest.mark.parametrize("flag, shown", [(None, False), ("--progress", True),
                                         ("--quiet", False), ("--no-progress", False)])
def test_run_draws_the_bar_only_when_asked_off_a_terminal(tmp_path, flag, shown):
    """CliRunner's stderr is not a terminal: by default no bar; --progress forces it."""
    args = ["run", "crossing", "--scans", "6", "--seed", "1", "--out", str(tmp_path / "r"),
            "--json"] + ([flag] if flag else [])
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 0, r.output
    assert bar_written(r.stderr) is shown, r.stderr


def test_track_and_montecarlo_write_no_bar_into_a_pipe(tmp_path):
    runner = CliRunner()
    r = runner.invoke(cli, ["run", "crossing", "--scans", "6", "--out", str(tmp_path / "r")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(cli, ["track", str(tmp_path / "r" / "plots.csv"), "--out",
                            str(tmp_path / "t.csv")])
    assert r.exit_code == 0, r.output
    assert not bar_written(r.stderr), r.stderr
    r = runner.invoke(cli, ["montecarlo", "crossing", "--scans", "6", "--runs", "2",
                            "--trackers", "mht", "--workers", "1", "--out",
                            str(tmp_path / "mc")])
    assert r.exit_code == 0, r.output
    assert not bar_written(r.stderr), r.stderr
    r = runner.invoke(cli, ["montecarlo", "crossing", "--scans", "6", "--runs", "3",
                            "--trackers", "mht", "--workers", "1", "--progress", "--out",
                            str(tmp_path / "mc")])
    assert r.exit_code == 0, r.output
    assert bar_written(r.stderr), r.stderr
