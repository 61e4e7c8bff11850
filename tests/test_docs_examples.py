"""The Python examples of docs/architecture.md run as written, and do what they say."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

DOC = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"
BLOCKS = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)


def test_the_page_has_its_three_examples() -> None:
    assert len(BLOCKS) == 3


@pytest.mark.parametrize("i", range(len(BLOCKS)))
def test_example_runs(i: int) -> None:
    ns: dict[str, object] = {"__name__": f"architecture_example_{i}"}
    exec(compile(BLOCKS[i], f"docs/architecture.md[{i}]", "exec"), ns)
    tracks = ns["tracks"]
    n_ids = len(np.unique(tracks.track_id))
    assert 2 <= n_ids <= 8  # crossing has 4 targets: a sensible example, not a false-track storm
    if "EntryZoneBirth" in ns:  # every track starts inside the zone: its first row is there
        first = np.unique(tracks.track_id, return_index=True)[1]
        x, y = tracks.x[first], tracks.y[first]
        # the east half of crossing (x >= 0): targets 2 and 3 start in the west half;
        # 300 m covers the first state's filtering of the birth plot (σ = 10 m)
        assert ((x >= -300) & (np.abs(y) <= 4300)).all()
        assert len(first) == 4 and sorted(tracks.scan[first].tolist()) == [1, 1, 57, 78]
    if "ForgettingUniformClutter" in ns:
        # the estimate follows the scenario's uniform density (6.25e-7 per m² per scan)
        kappa = ns["tracker"].clutter.kappa
        assert abs(kappa / ns["scenario"].mean_clutter_density() - 1) < 0.25
