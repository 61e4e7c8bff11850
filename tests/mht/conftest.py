"""Fixtures for the MHT tests (helpers in ``crossing_fixture.py``)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "reference"))  # reference implementations

from crossing_fixture import Simulated, simulate


@pytest.fixture(scope="session")
def crossing40() -> Simulated:
    return simulate(clutter_rate=40.0, seed=1)


@pytest.fixture(scope="session")
def crossing10() -> Simulated:
    return simulate(clutter_rate=10.0, seed=2)
