"""The per-frame DEBUG line (``-vv``, :mod:`mhtrack.pipeline.frame_log`): one line per
frame, its fields checked against the frames of the source and the tracks written; none
of it runs when DEBUG is off, and it changes no output."""

from __future__ import annotations

import logging
import re
from pathlib import Path

import numpy as np
import pyarrow.csv as pacsv
import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli

LINE = re.compile(r"frame (\d+) t=(-?[\d.]+) s radar ([\d,]+|-): (\d+) plots, (\d+) "
                  r"confirmed \+ (\d+) tentative tracks, (\d+) hypotheses in (\d+) trees, "
                  r"clutter (\S+) /m² \(mean at the plots\), ([\d.]+) ms$")


def _frames_logged(log: Path) -> list[dict]:
    out = []
    for text in log.read_text(encoding="utf-8").splitlines():
        if "mhtrack.pipeline DEBUG: frame " not in text:
            continue
        m = LINE.search(text)
        assert m, text
        k, t, radar, n, conf, tent, hyp, trees, kappa, ms = m.groups()
        out.append({"index": int(k), "time": float(t), "radar": radar, "plots": int(n),
                    "confirmed": int(conf), "tentative": int(tent), "hyp": int(hyp),
                    "trees": int(trees), "kappa": kappa, "ms": float(ms)})
    return out


def _invoke(*args: object) -> None:
    r = CliRunner().invoke(cli, [str(a) for a in args])
    assert r.exit_code == 0, r.output


@pytest.fixture(scope="module")
def crossing(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("crossing")
    _invoke("simulate", "crossing", "--scans", "12", "--seed", "2", "-o", d, "-q")
    return d


@pytest.mark.parametrize("tracker", ["mht", "mht-agmm"])
def test_one_line_per_scan_with_the_scans_plots_and_the_tracks_reported(
        crossing: Path, tmp_path: Path, tracker: str) -> None:
    log, out = tmp_path / "run.log", tmp_path / "tracks.csv"
    _invoke("-vv", "track", crossing / "plots.csv", "--tracker", tracker, "--output",
            "online", "-o", out, "--log-file", log, "-q")
    lines = _frames_logged(log)
    plots = pacsv.read_csv(crossing / "plots.csv")
    scan, time = plots.column("scan").to_numpy(), plots.column("time").to_numpy()
    tracks = pacsv.read_csv(out).column("scan").to_numpy()
    assert [ln["index"] for ln in lines] == list(range(1, 13))  # the 12 scans, in order
    for ln in lines:
        at = scan == ln["index"]
        assert ln["plots"] == at.sum()  # one sensor: nothing fused
        assert ln["time"] == pytest.approx(time[at][0], abs=5e-4)
        assert ln["radar"] == "0"
        # one sensor looks at every track: the confirmed ones are those reported
        assert ln["confirmed"] == (tracks == ln["index"]).sum()
        assert ln["confirmed"] + ln["tentative"] <= ln["trees"] <= ln["hyp"]
        assert ln["ms"] >= 0
    if tracker == "mht":  # the known intensity, P1's 1e-9 per m² (above the floor)
        assert {ln["kappa"] for ln in lines} == {"1e-09"}
    else:
        assert all(float(ln["kappa"]) > 0 for ln in lines)


def test_timed_plots_one_line_per_frame_of_the_source(tmp_path: Path) -> None:
    pytest.importorskip("pyproj")
    from mhtrack.pipeline.inputs import open_input

    d = tmp_path / "or"
    _invoke("simulate", "opensky-radars", "--seed", "1", "-o", d, "-q")
    rows = (d / "plots.csv").read_text().splitlines()[:1501]
    (d / "plots.csv").write_text("\n".join(rows) + "\n")
    log = tmp_path / "run.log"
    _invoke("track", d / "plots.csv", "--sensors", d / "sensors.toml", "-o",
            tmp_path / "t.csv", "-vv", "--log-file", log, "-q")
    lines = _frames_logged(log)
    frames = list(open_input(d / "plots.csv", sensors_file=d / "sensors.toml"))
    assert len(lines) == len(frames) > 10
    for ln, f in zip(lines, frames, strict=True):
        assert ln["index"] == f.index and ln["plots"] == len(f)
        assert ln["time"] == pytest.approx(f.time, abs=5e-4)
        ids = sorted(set(f.sensor.tolist()))
        assert ln["radar"] == (",".join(map(str, ids)) or "-")
        assert ln["kappa"] == "-" if len(f) == 0 else float(ln["kappa"]) > 0
    assert sum(ln["plots"] for ln in lines) == 1500


def test_debug_lines_change_no_output(crossing: Path, tmp_path: Path) -> None:
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    _invoke("track", crossing / "plots.csv", "-o", a, "-q")
    _invoke("track", crossing / "plots.csv", "-o", b, "-vv", "--log-file",
            tmp_path / "log", "-q")
    assert a.read_bytes() == b.read_bytes()


def test_nothing_is_computed_when_debug_is_off(crossing: Path, monkeypatch) -> None:
    from mhtrack.pipeline import run as run_module
    from mhtrack.pipeline.run import Pipeline

    calls = []
    monkeypatch.setattr(run_module, "log_frame", lambda *a: calls.append(a))
    logger = logging.getLogger("mhtrack.pipeline")
    old = logger.level
    try:
        logger.setLevel(logging.INFO)
        result = Pipeline.open(crossing / "plots.csv").run()
        assert calls == [] and len(result.stats) == 12
        logger.setLevel(logging.DEBUG)
        Pipeline.open(crossing / "plots.csv").run()
        assert len(calls) == 12  # the same run at DEBUG: one call per frame
    finally:
        logger.setLevel(old)


def test_the_line_is_formatted_lazily() -> None:
    """The message's arguments go to the record; it is formatted only by a handler."""
    from mhtrack.mht import MHTTracker
    from mhtrack.pipeline.frame_log import FORMAT, log_frame
    from mhtrack.records import Scan

    records: list[logging.LogRecord] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            records.append(record)

    logger = logging.getLogger("test.frame_log")
    logger.setLevel(logging.DEBUG)
    logger.addHandler(Keep())
    logger.propagate = False
    trk = MHTTracker()
    scan = Scan.from_positions(1, 2.5, np.array([[0.0, 0.0], [500.0, 0.0]]), sensor=7)
    trk.step(scan)
    log_frame(logger, scan, trk, trk.last_stats)
    (rec,) = records
    assert rec.msg == FORMAT and isinstance(rec.args, tuple) and len(rec.args) == 10
    # two plots 500 m apart on the first scan: two new trees, nothing confirmed yet
    m = LINE.match(rec.getMessage())
    assert m and m.group(1, 2, 3, 4, 5, 8, 9) == ("1", "2.500", "7", "2", "0", "2", "1e-09")
