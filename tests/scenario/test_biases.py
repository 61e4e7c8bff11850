"""Registration biases in the simulation (mhtrack.scenario.biases, sweep.radar_plots):
the biased plots against the unbiased ones of the same seed (same noise streams)."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.scenario import apply_overrides, load_scenario, preset, simulate
from mhtrack.scenario.biases import parse_bias, with_biases


def _sim(biases=()):  # type: ignore[no-untyped-def]
    sc = apply_overrides(preset("opensky-radars"), scans=12)
    return simulate(with_biases(sc, biases), seed=2)


def test_biased_plots_are_the_unbiased_with_the_bias() -> None:
    clean = _sim()
    biased = _sim([parse_bias("1:range=200,azimuth=-0.12"),
                   parse_bias("2:gain=1.002,azimuth=0.08")])
    a, b = clean.plots, biased.plots
    assert np.array_equal(a.time, b.time) and np.array_equal(a.origin, b.origin)
    tgt = a.origin >= 0
    assert tgt.sum() > 100
    for sid, dr, g, daz in ((1, 200.0, 1.0, -0.12), (2, 0.0, 1.002, 0.08), (3, 0.0, 1.0, 0.0)):
        m = tgt & (a.sensor == sid)
        # r_b = g r + Δr + n, r_a = r + n: r_b − r_a = (g − 1) r + Δr, r ≈ r_a within n
        np.testing.assert_allclose(b.range[m] - a.range[m], (g - 1) * a.range[m] + dr,
                                   atol=abs(g - 1) * 5 * 80 + 1e-6)
        dθ = (b.bearing[m] - a.bearing[m] + 180) % 360 - 180
        np.testing.assert_allclose(dθ, daz, atol=1e-9)
        c = ~tgt & (a.sensor == sid)  # clutter is drawn in the measured space
        assert np.array_equal(a.range[c], b.range[c])


def test_no_bias_is_the_former_simulation() -> None:
    a = _sim()
    b = _sim([parse_bias("1:range=0,gain=1,azimuth=0")])
    assert np.array_equal(a.plots.range, b.plots.range)
    assert np.array_equal(a.plots.x, b.plots.x)


def test_biases_travel_with_the_scenario_file(tmp_path) -> None:
    from mhtrack.io import write_scenario_toml

    sc = with_biases(apply_overrides(preset("opensky-radars"), scans=3),
                     [parse_bias("3:range=-150.5,gain=0.999,azimuth=0.2")])
    write_scenario_toml(sc.to_dict(), tmp_path / "s.toml")
    back = load_scenario(tmp_path / "s.toml")
    r = {s.id: s for s in back.sensors}
    assert (r[3].range_bias, r[3].range_gain, r[3].azimuth_bias_deg) == (-150.5, 0.999, 0.2)
    assert (r[1].range_bias, r[1].range_gain, r[1].azimuth_bias_deg) == (0.0, 1.0, 0.0)
    assert "range_bias" not in str(apply_overrides(preset("opensky-radars"), scans=3)
                                   .to_dict())


@pytest.mark.parametrize("text", ["1", "x:range=1", "1:range", "1:speed=3", "1:range=abc",
                                  "1:"])
def test_bad_bias_text_is_refused(text: str) -> None:
    with pytest.raises(ValueError, match="bias"):
        parse_bias(text)


def test_bias_on_an_unknown_radar_is_refused() -> None:
    with pytest.raises(ValueError, match="sensor 9"):
        with_biases(preset("opensky-radars", scans=2), [(9, {"range_bias": 1.0})])
    with pytest.raises(ValueError, match="range_gain"):
        with_biases(preset("opensky-radars", scans=2), [(1, {"range_gain": 3.0})])
