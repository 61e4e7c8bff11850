"""Fast start (issue 18): the command line's entry module loads no heavy library.

What a fresh interpreter has in ``sys.modules`` after the import — behaviour, not time
(the whole-process timings are in ``benchmarks/run.py``)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[2] / "src")
HEAVY = ("matplotlib", "pandas", "dask", "pyarrow", "scipy", "sklearn", "pyproj", "numpy")


def _loaded(code: str) -> list[str]:
    env = {**os.environ, "PYTHONPATH": SRC}
    probe = (f"import sys; {code}; import json; "
             f"print(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}})))")
    out = subprocess.run([sys.executable, "-c", probe], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.splitlines()[-1])


@pytest.mark.parametrize("code", ["import mhtrack.cli.main", "import mhtrack"])
def test_entry_imports_no_heavy_library(code: str) -> None:
    loaded = _loaded(code)
    assert "mhtrack" in loaded  # the probe sees what it imported
    assert [m for m in HEAVY if m in loaded] == []


def test_records_still_reachable_from_the_package() -> None:
    """``mhtrack.Scan`` and friends load :mod:`mhtrack.records` on first use."""
    loaded = _loaded("import mhtrack; mhtrack.TrackTable")
    assert "numpy" in loaded


#: Libraries ``mhtrack track`` of a Cartesian one-scan CSV must not load (issue 18).
NOT_FOR_TRACK = ("pandas", "matplotlib", "dask", "sklearn", "pyproj", "scipy")


def test_track_of_one_scan_loads_no_heavy_library(tmp_path: Path) -> None:
    """The whole ``track`` command (read, track, write) in a fresh interpreter: what it
    loaded, and that it did its work (the tracks file is written)."""
    plots = tmp_path / "plots.csv"
    plots.write_text("scan,time,sensor,x,y\n1,1.0,0,691.2,688.8\n1,1.0,0,-2017.0,1520.5\n"
                     "1,1.0,0,3050.0,-410.0\n1,1.0,0,120.0,-2600.0\n")
    out = tmp_path / "tracks.csv"
    args = ["track", str(plots), "--out", str(out)]
    loaded = _loaded("from mhtrack.cli.main import cli; "
                     f"cli.main({args!r}, prog_name='mhtrack', standalone_mode=False)")
    assert out.read_text().startswith("scan,")
    assert {"mhtrack", "numpy", "pyarrow"} <= set(loaded)
    assert [m for m in NOT_FOR_TRACK if m in loaded] == []
