"""Which sensors the bias estimation estimates and which fix the gauge
(mhtrack.pipeline.registration.estimable), and the correction of a frame's plots."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.models.geodesy import polar_to_local
from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.models.registration import RadarBias
from mhtrack.pipeline.registration import Registration, estimable
from mhtrack.records import Scan


def _radar(i: int, lat: float) -> RadarSensor:
    return RadarSensor(i, "polar", pd=0.9, lat=lat, lon=-1.0, sigma_range=30.0,
                       sigma_bearing_deg=0.1, period=4.0)


RADARS = (_radar(4, 52.0), _radar(2, 52.5), _radar(7, 53.0))


def test_lowest_radar_is_the_default_reference() -> None:
    assert estimable(SensorSet(None, RADARS)) == ((4, 7), (2,))


def test_chosen_reference() -> None:
    assert estimable(SensorSet(None, RADARS), reference=7) == ((2, 4), (7,))
    with pytest.raises(ValueError, match="bias reference 9"):
        estimable(SensorSet(None, RADARS), reference=9)


def test_adsb_is_the_reference_and_every_radar_is_estimated() -> None:
    adsb = RadarSensor(10, "adsb", pd=0.99)
    assert estimable(SensorSet(None, (*RADARS, adsb))) == ((2, 4, 7), (10,))


def test_a_frame_is_corrected_with_the_prior() -> None:
    """A plot measured with the prior's bias is placed where the unbiased one would be."""
    ss = SensorSet(None, RADARS)
    bias = RadarBias(200.0, 1.001, -0.1, (1.0, 1e-5, 0.01))
    reg = Registration(ss, prior={4: bias})
    lat, lon = ss.site_latlon(4)
    r, th = np.array([80e3, 150e3]), np.array([30.0, 200.0])
    true, _ = polar_to_local(ss.frame(), lat, lon, r, th, 30.0, 0.1)
    meas, _ = polar_to_local(ss.frame(), lat, lon, bias.range_gain * r + bias.range_offset,
                             th + bias.azimuth_deg, 30.0, 0.1)
    scan = Scan(0, 1.0, meas.reshape(-1, 2), np.array([4, 4]), np.array([0, 1]),
                R=np.tile(np.eye(2), (2, 1, 1)))
    out = reg.correct(scan)
    np.testing.assert_allclose(out.z, true.reshape(-1, 2), atol=1e-4)
    ref = Scan(1, 2.0, meas.reshape(-1, 2), np.array([2, 2]), np.array([2, 3]))
    assert reg.correct(ref).z is not None
    np.testing.assert_array_equal(reg.correct(ref).z, ref.z)  # the reference: untouched
