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
