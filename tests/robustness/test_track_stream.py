"""``mhtrack track`` streams its tracks file into a temporary as frames complete: a
SIGTERM then leaves the old output and no temporary; a SIGKILL leaves a recognisable
temporary that the next run in that folder removes (issue 33, deliverables 3 and 6)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from mhtrack.io import atomic, write_plots
from mhtrack.io.atomic import is_temporary
from mhtrack.io.sensors import write_sensors
from mhtrack.scenario import preset, simulate
from mhtrack.scenario.overrides import apply_overrides

SRC = str(Path(atomic.__file__).parents[2])

# chunks of 5 rows, so the temporary exists after a few frames; the frame after the
# seeded one at which a temporary exists waits to be killed
_TRACKING = textwrap.dedent("""
    import os, sys, time
    sys.path.insert(0, {src!r})
    from mhtrack.io.atomic import is_temporary
    from mhtrack.sinks import files
    files.TracksFileSink.__init__.__kwdefaults__["chunk_rows"] = 5
    from mhtrack.mht import MHTTracker
    real = MHTTracker.step
    calls = [0]
    folder = os.path.dirname(sys.argv[sys.argv.index("--out") + 1])
    def step(self, scan):
        calls[0] += 1
        tmp = [n for n in os.listdir(folder) if is_temporary(n)]
        if calls[0] >= int(sys.argv[1]) and tmp:
            print(tmp[0], flush=True)
            while True:
                time.sleep(0.01)
        return real(self, scan)
    MHTTracker.step = step
    from mhtrack.cli.main import cli
    cli(sys.argv[2:], prog_name="mhtrack")
""")


@pytest.fixture(scope="module")
def plots(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("sim")
    sc = apply_overrides(preset("opensky-radars"), scans=8)
    write_plots(simulate(sc, seed=1).plots, d / "plots.csv")
    write_sensors(sc.sensor_set(), d / "sensors.toml")
    return d / "plots.csv"


def _start(tmp_path: Path, plots: Path, frame: int, out: Path) -> tuple[subprocess.Popen[str],
                                                                          Path]:
    script = tmp_path / "cmd.py"
    script.write_text(_TRACKING.format(src=SRC))
    # the history streams its rows as they become final (the smoothed default waits
    # SMOOTHING_LAG_S of data time, longer than this scene)
    p = subprocess.Popen([sys.executable, str(script), str(frame), "track", str(plots),
                          "--out", str(out), "--quiet", "--output", "history"],
                         stdout=subprocess.PIPE, text=True)
    name = p.stdout.readline().strip()  # type: ignore[union-attr]
    return p, out.parent / name


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
@pytest.mark.parametrize("frame", list(np.random.default_rng(27).integers(5, 80, 2)))
def test_sigterm_while_streaming_keeps_the_old_file_and_no_temporary(
        tmp_path: Path, plots: Path, frame: int, suffix: str) -> None:
    out = tmp_path / "out" / f"tracks{suffix}"
    out.parent.mkdir()
    out.write_text("old\n")
    p, tmp = _start(tmp_path, plots, int(frame), out)
    assert is_temporary(tmp) and tmp.parent == out.parent  # rows streamed already
    p.send_signal(signal.SIGTERM)
    assert p.wait() == 143
    assert out.read_text() == "old\n" and os.listdir(out.parent) == [out.name]


def test_sigkill_while_streaming_leaves_a_temporary_the_next_run_removes(
        tmp_path: Path, plots: Path) -> None:
    out = tmp_path / "out" / "tracks.csv"
    out.parent.mkdir()
    p, tmp = _start(tmp_path, plots, 20, out)
    p.kill()
    p.wait()
    assert tmp.exists() and not out.exists()  # SIGKILL cannot be caught
    r = subprocess.run([sys.executable, "-c", "from mhtrack.cli.main import main; main()",
                        "track", str(plots), "--out", str(out), "--quiet"],
                       env={**os.environ, "PYTHONPATH": SRC}, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert not tmp.exists() and os.listdir(out.parent) == [out.name]
    assert out.read_text().startswith("frame,time,track_id,")
