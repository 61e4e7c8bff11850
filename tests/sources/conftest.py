"""Fixtures of the sources' tests: two minutes of simulated opensky-radars (three rotating
radars, ~3 100 plots) as a timed plots table and as recordings (``mhtrack export``), and
the frames today's readers give for them (the reference)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mhtrack.records import Scan

#: The Scan fields that must be equal, bit for bit.
FIELDS = ("index", "time", "rows", "sensor", "z", "R", "t", "origin")


@pytest.fixture(scope="session")
def opensky2(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``mhtrack simulate opensky-radars --seed 1 --scans 12 --no-attributes``: plots.csv,
    sensors.toml. Positions only, as the feeds' frames are compared plot by plot (a
    plot's flight level would enter its ground range)."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    out = tmp_path_factory.mktemp("opensky2")
    r = CliRunner().invoke(cli, ["simulate", "opensky-radars", "--seed", "1", "--scans",
                                 "12", "--no-attributes", "--out", str(out)])
    assert r.exit_code == 0, r.output
    return out


def differences(a: list[Scan], b: list[Scan], shift: float = 0.0,
                shift_from: float = np.inf) -> list[str]:
    """Where two frame lists differ (``b``'s times less ``shift`` from time
    ``shift_from`` on); empty when identical."""
    out = [] if len(a) == len(b) else [f"{len(a)} frames vs {len(b)}"]
    for x, y in zip(a, b, strict=False):
        for f in FIELDS:
            u, v = getattr(x, f), getattr(y, f)
            if f in ("time", "t") and shift and v is not None:
                v = np.where(np.asarray(v) >= shift_from + shift, np.asarray(v) - shift, v)
            if (u is None) != (v is None) or (u is not None and not np.array_equal(u, v)):
                out.append(f"frame {x.index}: {f}")
    return out
