"""Fixtures for the MHT tests (helpers in ``crossing_fixture.py``)."""

from __future__ import annotations

import pytest
from crossing_fixture import Simulated, simulate


@pytest.fixture(scope="session")
def crossing40() -> Simulated:
    return simulate(clutter_rate=40.0, seed=1)


@pytest.fixture(scope="session")
def crossing10() -> Simulated:
    return simulate(clutter_rate=10.0, seed=2)
