"""``mhtrack track REC --sector-frames``: a recording's frames cut at its radars' own
CAT034 sector crossings (issue 28 item 5), the same as the library's
``AsterixSource(sectors=True)``; a plots table, which has no crossings, is refused."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from click.testing import CliRunner
from sim_recording import simulated_recording

from mhtrack.cli.main import cli
from mhtrack.io import read_tracks
from mhtrack.io.sensors import read_sensors
from mhtrack.pipeline import Pipeline, TrackOptions
from mhtrack.sinks import TrackCollector
from mhtrack.sources.recording import AsterixSource


@pytest.fixture(scope="module")
def rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(tmp_path_factory.mktemp("sectors"), seed=3, scans=4)


def _frames(rec: Path, sectors: bool) -> list[tuple[int, float]]:
    source = AsterixSource(rec / "radar.ast", sensors=read_sensors(rec / "sensors.toml"),
                           sectors=sectors)
    return [(int(f.index), float(f.time)) for f in source]


def test_track_cuts_frames_at_the_sectors_as_the_source_does(rec: Path) -> None:
    sectors, eighths = _frames(rec, True), _frames(rec, False)
    assert sectors != eighths  # the option changes the frames: the test can tell
    out = rec / "t.csv"
    r = CliRunner().invoke(cli, ["track", str(rec / "radar.ast"), "--sensors",
                                 str(rec / "sensors.toml"), "--sector-frames", "--output",
                                 "online", "--out", str(out), "-q"])
    assert r.exit_code == 0, r.output
    got = read_tracks(out)
    ref = TrackCollector("online")
    Pipeline.open(str(rec / "radar.ast"), TrackOptions(output="online"),
                  sensors_file=str(rec / "sensors.toml"), sectors=True).run([ref])
    want = ref.tracks()
    assert got.track_id.tolist() == want.track_id.tolist()
    assert np.allclose(got.x, want.x, atol=1e-6) and np.allclose(got.y, want.y, atol=1e-6)
    # and the flag is what made them: without it, the eighths' rows
    plain = TrackCollector("online")
    Pipeline.open(str(rec / "radar.ast"), TrackOptions(output="online"),
                  sensors_file=str(rec / "sensors.toml")).run([plain])
    other = plain.tracks()
    assert (len(other) != len(got) or other.scan.tolist() != got.scan.tolist()
            or not np.allclose(other.x, got.x))


def test_a_plots_table_is_refused_in_one_line(rec: Path) -> None:
    r = CliRunner().invoke(cli, ["track", str(rec / "plots.csv"), "--sensors",
                                 str(rec / "sensors.toml"), "--sector-frames", "--out",
                                 str(rec / "t2.csv")])
    assert r.exit_code != 0
    line = r.output.strip().splitlines()[-1]
    assert "plots.csv is a plots table" in line and "CAT034 sector crossings" in line
    assert not (rec / "t2.csv").exists()
