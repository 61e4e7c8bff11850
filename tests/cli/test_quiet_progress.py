"""``-q/--quiet`` and ``--progress`` on every command (issue 31): the bar only on a
terminal or with ``--progress`` (CliRunner's stderr is no terminal), never with
``--quiet``; ``--quiet`` prints nothing for a successful run but the results asked for,
and its warnings still reach ``--log-file``."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli


def _run(*args: object):
    r = CliRunner().invoke(cli, [str(a) for a in args])
    assert r.exit_code == 0, r.output
    return r


def bar_drawn(stderr: str) -> bool:
    """tqdm's bar: ``desc: 40%|████  | 4/10 [...]`` (or ``N unit [...]`` without total)."""
    return "%|" in stderr or "/s]" in stderr


@pytest.fixture(scope="module")
def crossing(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("c")
    _run("simulate", "crossing", "--scans", "8", "--seed", "1", "-o", d, "--quiet")
    _run("track", d / "plots.csv", "-o", d / "tracks.csv", "--quiet")
    return d


@pytest.fixture(scope="module")
def radars(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """opensky-radars' first 600 plots, their sensors file, tracks, and a recording."""
    pytest.importorskip("asterix.generated", reason="libasterix not installed")
    d = tmp_path_factory.mktemp("or")
    _run("simulate", "opensky-radars", "--seed", "1", "-o", d, "--quiet")
    rows = (d / "plots.csv").read_text().splitlines()[:601]
    (d / "plots.csv").write_text("\n".join(rows) + "\n")
    _run("export", d / "plots.csv", "--sensors", d / "sensors.toml", "-o", d / "rec.pcap",
         "-q")
    _run("track", d / "plots.csv", "--sensors", d / "sensors.toml", "-o", d / "t.csv", "-q")
    return d


def _long_commands(c: Path, d: Path, out: Path) -> dict[str, list[object]]:
    """The commands the issue gives a bar, each with its unit."""
    s = d / "sensors.toml"
    return {
        "frame": ["track", c / "plots.csv", "-o", out / "t.csv"],
        "plot": ["track", d / "rec.pcap", "--sensors", s, "-o", out / "r.csv"],
        "B": ["convert", d / "rec.pcap", out / "p.csv"],
        "row": ["export", d / "plots.csv", "--sensors", s, "-o", out / "x.pcap"],
        "row ": ["export", d / "t.csv", "--sensors", s, "--category", "062", "-o",
                 out / "x.ast"],
        "frame ": ["run", "crossing", "--scans", "5", "-o", out / "run"],
        "run": ["montecarlo", "crossing", "--scans", "5", "--runs", "2", "--trackers", "mht",
                "--workers", "1", "-o", out / "mc"],
    }


def test_bars_only_with_progress_never_into_a_pipe_nor_with_quiet(crossing, radars,
                                                                   tmp_path):
    for unit, args in _long_commands(crossing, radars, tmp_path).items():
        shown = _run(*args, "--progress")
        assert bar_drawn(shown.stderr) and f"{unit.strip()}/s" in shown.stderr, (args,
                                                                                shown.stderr)
        plain = _run(*args)
        assert not bar_drawn(plain.stderr), (args, plain.stderr)
        assert plain.stdout  # the info lines
        for quiet in (["--quiet", "--progress"], ["--progress", "-q"]):  # --quiet wins
            r = _run(*args, *quiet)
            assert r.stdout == "" and r.stderr == "", (args, r.output)


def test_group_options_count_as_the_commands(crossing, tmp_path):
    r = _run("--progress", "track", crossing / "plots.csv", "-o", tmp_path / "t.csv")
    assert bar_drawn(r.stderr)
    r = _run("-q", "track", crossing / "plots.csv", "-o", tmp_path / "t.csv", "--progress")
    assert r.stdout == "" and r.stderr == ""
    r = _run("--no-progress", "track", crossing / "plots.csv", "-o", tmp_path / "t.csv")
    assert r.stdout and not bar_drawn(r.stderr)  # the former spelling: no bar, lines kept


@pytest.mark.parametrize("args", [
    ["simulate", "crossing", "--scans", "4", "-o", "{tmp}/s"],
    ["evaluate", "{c}/tracks.csv", "{c}/truth.csv", "-o", "{tmp}/m.json", "--json"],
    ["plot", "{c}", "-o", "{tmp}/scene.png"],
    ["clutter", "crossing", "--scans", "4", "-o", "{tmp}/cl"],
    ["reproduce", "p2", "--runs", "1", "--workers", "1", "-o", "{tmp}/p2"],
], ids=lambda a: a[0])
def test_quiet_prints_nothing_for_a_successful_run(crossing, tmp_path, args):
    args = [a.format(c=crossing, tmp=tmp_path) for a in args]
    loud = _run(*args)
    assert loud.stdout  # what --quiet silences
    r = _run(*args, "--quiet")
    assert r.stdout == "" and r.stderr == "", r.output


def test_quiet_keeps_the_results_asked_for(crossing):
    r = _run("evaluate", crossing / "tracks.csv", crossing / "truth.csv", "-q")
    assert "OSPA" in r.stdout and r.stderr == ""
    r = _run("evaluate", crossing / "tracks.csv", crossing / "truth.csv", "--json", "-q")
    assert r.stdout.startswith("{") and r.stderr == ""


def test_quiet_silences_warnings_on_stderr_not_in_the_log_file(tmp_path):
    # mht keeps P1's κ = 1e-9 on crossing's ~6e-7 per m²: run warns (warn_known_kappa)
    args = ["run", "crossing", "--scans", "4", "--tracker", "mht", "-o", tmp_path / "r"]
    assert "WARNING" in _run(*args).stderr
    log = tmp_path / "run.log"
    r = _run(*args, "--quiet", "--log-file", log)
    assert r.stdout == "" and r.stderr == ""
    assert "WARNING" in log.read_text(encoding="utf-8")


def test_track_of_a_recording_shows_its_survey_in_bytes_then_its_plots(radars, tmp_path):
    r = _run("track", radars / "rec.pcap", "--sensors", radars / "sensors.toml", "-o",
             tmp_path / "t.csv", "--progress")
    survey, plots = r.stderr.find("survey:"), r.stderr.find("plot/s")
    assert 0 <= survey < plots and "B/s" in r.stderr[:plots], r.stderr
    assert not bar_drawn(_run("track", radars / "rec.pcap", "--sensors",
                              radars / "sensors.toml", "-o", tmp_path / "u.csv").stderr)
