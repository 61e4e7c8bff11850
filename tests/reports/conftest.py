"""Fixtures of the HTML report tests: the headless Chromium of ``tests/helpers/browser.py``
(``chromium``, ``open_in_browser``; skipped, with the reason, where no Chromium is
installed) and the directories to report on, made once per session through the CLI."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path
from typing import Any

import pytest
from browser import PageCheck, check_page, chromium_path  # tests/helpers


@pytest.fixture(scope="session")
def chromium() -> str:
    """Chromium's path; the test is skipped, with the reason, where there is none."""
    exe = chromium_path()
    if exe is None:
        pytest.skip("no Chromium on PATH (apt-get install chromium, or set "
                    "MHTRACK_CHROMIUM): the HTML report is not checked in a browser")
    return exe


def read_track_ids(path: Path) -> tuple[set[str], bool]:
    """The track ids of a tracks CSV with a confirmed row, and whether any row is
    tentative (before confirmation): the scene draws one trace per confirmed id and one
    for all tentative rows."""
    confirmed, tentative = set(), False
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            if row.get("tentative") == "1":
                tentative = True
            else:
                confirmed.add(row["track_id"])
    return confirmed, tentative


@pytest.fixture(scope="session")
def track_ids():
    """:func:`read_track_ids`, for the report tests."""
    return read_track_ids


# --- directories to report on, made once per session through the CLI ---------------------

def invoke(*args: str) -> tuple[int, str, str]:
    """``mhtrack ARGS`` in this process: exit code, stdout, stderr."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    r = CliRunner().invoke(cli, list(args))
    return r.exit_code, r.stdout, r.stderr


@pytest.fixture(scope="session")
def run_dir(tmp_path_factory) -> Path:
    """``run crossing --seed 1 --scans 30 --report``: a run with its report.html."""
    out = tmp_path_factory.mktemp("html-run") / "c"
    code, _, err = invoke("run", "crossing", "--seed", "1", "--scans", "30", "--out",
                          str(out), "--report", "--no-progress")
    assert code == 0, err
    return out


@pytest.fixture(scope="session")
def geo_dir(tmp_path_factory) -> Path:
    """``simulate opensky-radars --no-attributes`` (4 scans) and ``track``: timed plots
    of three radars at WGS-84 sites, a sensors file, no metrics.json. No secondary-radar
    attributes: the hover test writes flight levels and codes of its own to check them."""
    out = tmp_path_factory.mktemp("html-geo")
    code, _, err = invoke("simulate", "opensky-radars", "--seed", "1", "--scans", "4",
                          "--no-attributes", "--out", str(out))
    assert code == 0, err
    code, _, err = invoke("track", str(out / "plots.csv"), "--out", str(out / "tracks.csv"),
                          "--no-progress")
    assert code == 0, err
    return out


@pytest.fixture(scope="session")
def recording_dir(geo_dir, tmp_path_factory) -> Path:
    """A recording as a user has it: plots, sensors and tracks, no truth, no scenario."""
    out = tmp_path_factory.mktemp("html-recording") / "recording"
    out.mkdir()
    for name in ("plots.csv", "sensors.toml", "tracks.csv"):
        shutil.copy(geo_dir / name, out / name)
    return out


@pytest.fixture(scope="session")
def study_dir(tmp_path_factory) -> Path:
    """``montecarlo crossing``: two trackers, 3 runs of 20 scans, in this process."""
    out = tmp_path_factory.mktemp("html-study") / "mc"
    code, _, err = invoke("montecarlo", "crossing", "--trackers", "mht-gmm,mht-agmm",
                          "--runs", "3", "--scans", "20", "--workers", "1", "--out",
                          str(out), "--no-progress")
    assert code == 0, err
    return out


@pytest.fixture
def open_in_browser(chromium, tmp_path):
    """``open_in_browser(page) -> PageCheck``, screenshots under the test's tmp folder."""

    def run(page: Path, **kw: Any) -> PageCheck:
        return check_page(chromium, page, tmp_path / "browser", **kw)

    return run


NATURAL_EARTH = Path(__file__).parents[1] / "io" / "data" / "naturalearth"


@pytest.fixture
def cached_coastlines(tmp_path, monkeypatch):
    """The tiny Natural Earth fixture in a cache of this test's own; any download fails
    the test (never at test time)."""
    from mhtrack.io import basemap

    shutil.copytree(NATURAL_EARTH, tmp_path / "cache" / "naturalearth")
    monkeypatch.setenv("MHTRACK_CACHE", str(tmp_path / "cache"))

    def no_network(url):
        raise AssertionError(f"downloaded {url} at test time")

    monkeypatch.setattr(basemap, "_download", no_network)
    return tmp_path / "cache" / "naturalearth"
