"""The tracking pipeline's defaults: P1's new-target rate scaled to the surveillance area."""

import logging

import pytest

from mhtrack.build import birth_density_for_area, default_config
from mhtrack.experiments import run_scenario
from mhtrack.mht import MHTConfig
from mhtrack.scenario import preset


def test_p1_region_gives_p1_birth_density():
    # P1 §3: λv = 1e−7 per m² over [−4000, 4000]² m = 6.4e7 m²
    assert default_config(preset("crossing")).new_target_density == pytest.approx(1e-7)
    assert birth_density_for_area(6.4e7 * 100) == pytest.approx(1e-9)
    assert default_config() == MHTConfig()
    with pytest.raises(ValueError, match="area"):
        birth_density_for_area(0.0)


def test_real_aircraft_are_tracked_with_the_defaults(caplog):
    """OpenSky: 84 real aircraft, 10 s scans, two radars. With P1's λv taken literally
    (1e−7 per m² over ~2.9e11 m²) every plot became a confirmed track (5 809 tracks);
    with the scaled default the tracks are about one per aircraft."""
    sc = preset("opensky")
    assert default_config(sc).new_target_density < 1e-10
    with caplog.at_level(logging.ERROR):
        r = run_scenario(sc, 1, "mht-agmm", cutoff=2000.0)
    s = r.summary()
    assert 84 <= s["n_tracks"] <= 110
    assert s["mota"] > 0.85
    assert s["rcc"] > 0.9
    assert s["id_switches"] < 40
