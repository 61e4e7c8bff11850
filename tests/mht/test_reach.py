"""A radar's reach learned from its plots (mht/reach.py): simulated plots with a known
max_range per azimuth and a blind sector, outliers, forgetting, the state round trip, and
the order statistic against a brute-force computation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.mht.reach import ReachEstimator

PERIOD = 4.0


def _true_reach(bearing: np.ndarray) -> np.ndarray:
    """150 km east (0–180°), 100 km west, blind from 200° to 250°."""
    r = np.where(np.mod(bearing, 360.0) < 180.0, 150e3, 100e3)
    return np.where((bearing >= 200.0) & (bearing < 250.0), 0.0, r)


def _rotations(rng: np.random.Generator, k0: int, k1: int, per_rotation: int = 200
               ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per rotation: plots uniform in the area the radar sees (clutter)."""
    out = []
    for k in range(k0, k1):
        b = rng.uniform(0.0, 360.0, per_rotation)
        r = np.sqrt(rng.uniform(0.0, 1.0, per_rotation)) * _true_reach(b)
        seen = r > 0
        t = k * PERIOD + b / 360.0 * PERIOD
        out.append((t[seen], r[seen], b[seen]))
    return out


def _fed(rotations: int = 80, seed: int = 1, **kw: float) -> ReachEstimator:
    est = ReachEstimator({7: PERIOD}, **kw)  # type: ignore[arg-type]
    for t, r, b in _rotations(np.random.default_rng(seed), 0, rotations):
        est.update(7, t, r, b)
    return est


def test_known_max_range_and_blind_sector_recovered() -> None:
    est = _fed()
    env = est.envelope(7)
    assert env is not None and env.size == 16
    centre = (np.arange(16) + 0.5) * 22.5
    true = _true_reach(centre)
    blind = true == 0.0
    # each sector's reach within 3 % under its max_range (never above: plots lie inside)
    assert np.all(env[~blind] <= true[~blind])
    assert np.all(env[~blind] >= 0.97 * true[~blind])
    assert np.all(env[blind] == 0.0)
    # positions: inside 0.9 R within reach, beyond 1.1 R not, in the blind sector not
    b = np.linspace(0.0, 359.9, 721)
    inner = est.within(7, 0.9 * _true_reach(b), b)
    outer = est.within(7, 1.1 * np.maximum(_true_reach(b), 1.0), b)
    edge = np.min(np.abs(((b[:, None] - np.arange(0, 360, 22.5)[None, :]) + 180) % 360
                         - 180), axis=1) < 11.25  # within half a sector of a sector edge
    # blind sectors 9 and 10 (202.5–247.5°) whole; a position is judged by the sectors
    # half a sector either side of it
    interior_blind = (b >= 213.75) & (b < 236.25)
    assert inner[_true_reach(b) > 0].all()
    assert not outer[~edge].any()
    assert not est.within(7, np.full(interior_blind.sum(), 1e3), b[interior_blind]).any()
    lo, med, hi = est.summary()[7]
    assert lo == 0.0 and 97e3 < med <= 150e3 and 145.5e3 <= hi <= 150e3


def test_unknown_radar_sees_everywhere() -> None:
    est = ReachEstimator({7: PERIOD})
    assert est.envelope(7) is None and est.within(7, np.array([1e9]), np.array([0.0])).all()
    assert np.isnan(ReachEstimator().summary().get(3, (np.nan,))[0])


def test_one_far_outlier_does_not_extend_the_reach() -> None:
    est = _fed()
    genuine = est.maxima[7][:, 2].max()  # sector 2 (45–67.5°): the largest plot range
    assert genuine <= 150e3
    est.update(7, np.array([79 * PERIOD + 0.5]), np.array([400e3]), np.array([45.0]))
    assert est.envelope(7)[2] <= genuine  # type: ignore[index]  # rank 2: one plot is not evidence
    assert not est.within(7, np.array([300e3]), np.array([56.0])).any()
    est.update(7, np.array([80 * PERIOD + 0.5]), np.array([400e3]), np.array([45.0]))
    assert est.envelope(7)[2] == 400e3  # type: ignore[index]  # twice in the memory is


def test_a_shrinking_reach_is_forgotten_after_the_memory() -> None:
    est = _fed(memory=40.0)  # 10 rotations
    rng = np.random.default_rng(4)
    for t, r, b in _rotations(rng, 80, 95):  # the radar now sees half as far
        est.update(7, t, 0.5 * r, b)
    env = est.envelope(7)
    assert env is not None and env.max() <= 75e3


def test_state_round_trip() -> None:
    est = _fed(rotations=12)
    est.update(9, np.array([0.0, 11.0, 21.0]), np.array([5e3, 6e3, 7e3]),
               np.array([10.0, 10.0, 10.0]))  # a radar without a period: 10 s windows
    copy = ReachEstimator({7: PERIOD})
    copy.set_arrays(est.arrays())
    for sid in (7, 9):
        assert np.array_equal(copy.envelope(sid), est.envelope(sid))  # type: ignore[arg-type]
    assert copy.rotations(9) == 30 and copy.envelope(9)[0] == 6e3  # type: ignore[index]


def test_bad_parameters_refused() -> None:
    with pytest.raises(ValueError, match="rank ≥ 1"):
        ReachEstimator(rank=0)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 200.0), st.floats(0, 3e5), st.floats(0, 359.99)),
                min_size=1, max_size=80),
       st.integers(1, 3), st.floats(10.0, 120.0))
def test_envelope_is_the_rank_th_largest_rotation_maximum(
        plots: list[tuple[float, float, float]], rank: int, memory: float) -> None:
    plots.sort()
    t, r, b = (np.array(c) for c in zip(*plots, strict=True))
    est = ReachEstimator({1: 5.0}, sectors=4, memory=memory, rank=rank)
    for i in range(0, len(t), 7):  # in chunks, as frames arrive
        est.update(1, t[i:i + 7], r[i:i + 7], b[i:i + 7])
    k = np.floor((t - t[0]) / 5.0).astype(int)
    held = max(rank, int(np.ceil(memory / 5.0)))
    live = k > k.max() - held
    sector = np.floor(b / 90.0).astype(int)
    want = []
    for s in range(4):
        maxima = [max([rr for rr, kk, ss in zip(r[live], k[live], sector[live], strict=True)
                       if kk == q and ss == s], default=0.0) for q in sorted(set(k[live]))]
        maxima += [0.0] * max(0, rank - len(maxima))
        want.append(sorted(maxima)[-min(rank, len(set(k[live])))])
    assert np.array_equal(est.envelope(1), np.array(want))


def _coverage_frames(max_range: float | None):  # type: ignore[no-untyped-def]
    """A radar without a period (it looks everywhere each frame) whose plots reach 50 km
    in every direction, three frames 10 s apart, then leaves at 30 km and 80 km."""
    import dataclasses

    from async_fixture import ORIGIN, Radar

    from mhtrack.mht.coverage import RadarCoverage
    from mhtrack.models.radars import SensorSet
    from mhtrack.records import Scan

    radar = Radar(1, 0.0, 0.0, period=8.0, phase_deg=0.0)
    sensor = dataclasses.replace(radar.sensor(), period=None, max_range=max_range)
    cov = RadarCoverage(SensorSet(ORIGIN, (sensor,)))
    b = np.radians(np.arange(0.0, 360.0, 5.0))
    z = np.column_stack((50e3 * np.sin(b), 50e3 * np.cos(b)))
    leaves = np.array([[0.0, 0.0, 30e3, 0.0], [0.0, 0.0, 80e3, 0.0]])
    P = np.tile(np.diag([100.0, 1.0, 100.0, 1.0]), (2, 1, 1))
    looks = []
    for k in range(3):
        t = 10.0 * k
        scan = Scan(k, t, z, np.ones(len(z), np.int64), np.arange(len(z)),
                    t=np.full(len(z), t))
        looks.append(cov.detection(scan, leaves, P, np.full(2, t)))
    return cov, looks


def test_radar_coverage_charges_no_miss_beyond_the_learned_reach() -> None:
    """Without ``max_range``: a leaf beyond the farthest plots (80 km against 50 km) is
    looked at (a plot may update it) but not certainly (no miss charged); one within them
    is certain. With ``max_range`` in the file, the file's rule decides."""
    cov, looks = _coverage_frames(None)
    for lk in looks:
        np.testing.assert_array_equal(lk.certain, [True, False])
        assert (lk.pd > 0).all()
    np.testing.assert_allclose(cov.reach.summary()[1], (50e3, 50e3, 50e3), rtol=1e-12)
    _, looks = _coverage_frames(100e3)
    for lk in looks:
        np.testing.assert_array_equal(lk.certain, [True, True])


def test_radar_coverage_state_keeps_the_learned_reach() -> None:
    """``arrays``/``set_arrays`` carry the learned reach (a restored tracker continues)."""
    from mhtrack.mht.coverage import RadarCoverage

    cov, _ = _coverage_frames(None)
    fresh = RadarCoverage(cov.sensors)
    fresh.set_arrays(cov.arrays())
    assert fresh.reach.summary() == cov.reach.summary()
    np.testing.assert_array_equal(fresh.reach.within(1, np.array([30e3, 80e3]),
                                                     np.array([0.0, 0.0])), [True, False])
