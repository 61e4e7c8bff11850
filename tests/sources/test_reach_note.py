"""``mhtrack track`` reports each radar's reach learned from its plots when the sensors
file gives no ``max_range`` (issue 28, item 6), and nothing when it does."""

from __future__ import annotations

import re
from pathlib import Path

from click.testing import CliRunner

from mhtrack.cli.main import cli


def _track(plots: Path, sensors: Path, out: Path) -> str:
    r = CliRunner().invoke(cli, ["track", str(plots), "--sensors", str(sensors), "--out",
                                 str(out), "--no-progress"])
    assert r.exit_code == 0, r.output
    return r.stdout


def test_track_prints_the_learned_reach_per_radar(opensky2: Path, tmp_path: Path) -> None:
    full = (opensky2 / "sensors.toml").read_text()
    true = [float(v) for v in re.findall(r"^max_range = (\S+)$", full, re.M)]
    assert true, "the simulated sensors file gives max_range"
    assert "reach learned" not in _track(opensky2 / "plots.csv", opensky2 / "sensors.toml",
                                         tmp_path / "a.csv")
    bare = tmp_path / "bare.toml"
    bare.write_text(re.sub(r"^max_range = .*\n", "", full, flags=re.M))
    lines = [ln for ln in _track(opensky2 / "plots.csv", bare, tmp_path / "b.csv")
             .splitlines() if ln.startswith("reach learned")]
    assert len(lines) == 1
    found = re.findall(r"radar (\d+) (\d+)/(\d+)/(\d+) km", lines[0])
    assert len(found) == len(true)  # every radar, each with min ≤ median ≤ max
    for _, lo, med, hi in found:
        assert int(lo) <= int(med) <= int(hi) <= max(true) / 1e3  # never beyond the plots
