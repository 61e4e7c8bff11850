"""The registration-bias estimator (mhtrack.models.registration) on constructed
geometries: two radars 120 km apart seeing targets spread over their common coverage, the
plots made by the geodesy with a known bias, the estimate against it."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.models.geodesy import LocalFrame, local_to_polar, polar_to_local
from mhtrack.models.registration import BiasEstimator, RadarBias, correction_jacobian

FRAME = LocalFrame(52.0, -1.0)
SITES = {1: (52.0, -1.0), 2: (52.9, -0.2)}  # ~115 km apart
SR, SB = 30.0, 0.08  # σ range (m), σ azimuth (°) of both radars


def targets(n: int, seed: int = 0) -> np.ndarray:
    """(n, 2) local positions spread over 20–200 km of both radars."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(-150e3, 200e3, size=(4 * n, 2))
    ok = np.ones(len(p), bool)
    for lat, lon in SITES.values():
        r, _ = local_to_polar(FRAME, lat, lon, p[:, 0], p[:, 1])
        ok &= (r > 20e3) & (r < 200e3)
    return p[ok][:n]


def measure(sid: int, p: np.ndarray, bias: RadarBias, rng: np.random.Generator | None
            ) -> tuple[np.ndarray, np.ndarray]:
    """Radar ``sid``'s measured (range, azimuth) of ``p`` with ``bias`` (noise if rng)."""
    r, b = local_to_polar(FRAME, *SITES[sid], p[:, 0], p[:, 1])
    r, b = bias.range_gain * r + bias.range_offset, b + bias.azimuth_deg
    if rng is not None:
        r, b = r + rng.normal(0, SR, r.size), b + rng.normal(0, SB, b.size)
    return r, b


def place(sid: int, r: np.ndarray, b: np.ndarray, est: RadarBias
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rc, bc = est.correct(r, b)
    z, R = polar_to_local(FRAME, *SITES[sid], rc, bc, SR, SB)
    return z, R, correction_jacobian(rc, bc, est.range_gain)


def one_pass(est: BiasEstimator, meas: dict[int, tuple[np.ndarray, np.ndarray]],
             scale_C: float = 1.0) -> None:
    """Every target's pair (radar 2 against radar 1, same time) into ``est``, each
    placed with the estimate as it stands (the Kalman step's innovation)."""
    for i in range(len(meas[1][0])):
        z2, R2, H2 = place(2, meas[2][0][i:i + 1], meas[2][1][i:i + 1], est.bias(2))
        z1, R1, H1 = place(1, meas[1][0][i:i + 1], meas[1][1][i:i + 1], est.bias(1))
        est.update(2, H2[0], 1, H1[0], z2[0] - z1[0], scale_C * (R1[0] + R2[0]))


def test_correct_inverts_the_bias_model() -> None:
    b = RadarBias(180.0, 1.0015, -0.11)
    r, th = np.array([5e3, 150e3]), np.array([359.95, 12.0])
    rc, tc = b.correct(b.range_gain * r + b.range_offset, th + b.azimuth_deg)
    assert np.allclose(rc, r, rtol=0, atol=1e-9)
    assert np.allclose(tc, th, rtol=0, atol=1e-9)


def test_jacobian_matches_finite_differences_in_the_plane() -> None:
    """H of the flat-plane correction against central differences of p = r u(θ)."""
    rm, bm = np.array([80e3]), np.array([37.0])
    b0 = np.array([100.0, 0.001, np.radians(0.1)])

    def p(b: np.ndarray) -> np.ndarray:
        rc = (rm - b[0]) / (1 + b[1])
        th = np.radians(bm) - b[2]
        return np.stack((rc * np.sin(th), rc * np.cos(th)), axis=-1)[0]

    rc, bc = RadarBias(b0[0], 1 + b0[1], np.degrees(b0[2])).correct(rm, bm)
    H = correction_jacobian(rc, bc, 1 + b0[1])[0]
    for k, h in enumerate((1e-3, 1e-9, 1e-9)):
        e = np.zeros(3)
        e[k] = h
        assert np.allclose((p(b0 + e) - p(b0 - e)) / (2 * h), H[:, k], rtol=1e-5)


def test_noise_free_biases_recovered_exactly() -> None:
    """Noise-free plots: repeated passes (Gauss–Newton on the exact residual) converge to
    the true biases of radar 2 against reference radar 1."""
    true = RadarBias(200.0, 1.002, -0.12)
    p = targets(60)
    meas = {1: measure(1, p, RadarBias(), None), 2: measure(2, p, true, None)}
    prior = None
    for _ in range(4):
        est = BiasEstimator([2], prior=prior)
        one_pass(est, meas, scale_C=1e-6)
        b = est.bias(2)
        prior = {2: RadarBias(b.range_offset, b.range_gain, b.azimuth_deg, (500, 0.01, 0.5))}
    b = est.bias(2)
    assert b.range_offset == pytest.approx(200.0, abs=1e-3)
    assert b.range_gain == pytest.approx(1.002, abs=1e-8)
    assert b.azimuth_deg == pytest.approx(-0.12, abs=1e-6)
    assert est.bias(1) == RadarBias()  # the reference is held at zero


@pytest.mark.parametrize("true", [RadarBias(150.0, 0.9985, 0.09), RadarBias()])
def test_noisy_estimate_within_its_sigma(true: RadarBias) -> None:
    """With σr = 30 m, σθ = 0.08° noise, over 8 independent draws the normalised error
    of each component is within 3σ, and its mean square near 1 (the σ is honest);
    ``RadarBias()``: no bias, estimates consistent with zero."""
    z = []
    for seed in range(8):
        rng = np.random.default_rng(seed)
        p = targets(100, seed)
        meas = {1: measure(1, p, RadarBias(), rng), 2: measure(2, p, true, rng)}
        est = BiasEstimator([2])
        one_pass(est, meas)
        b = est.bias(2)
        err = np.array([b.range_offset - true.range_offset, b.range_gain - true.range_gain,
                        b.azimuth_deg - true.azimuth_deg])
        z.append(err / np.array(b.sigma))
    z = np.array(z)
    assert np.all(np.abs(z) < 3.5)
    assert 0.3 < float(np.mean(z**2)) < 2.5


def test_two_radars_against_an_absolute_reference() -> None:
    """An ADS-B-like reference (true positions, H = 0): both radars' biases estimated."""
    t1, t2 = RadarBias(-120.0, 1.0, 0.1), RadarBias(60.0, 1.001, -0.05)
    p = targets(80)
    m1, m2 = measure(1, p, t1, None), measure(2, p, t2, None)
    prior = None
    for _ in range(5):
        est = BiasEstimator([1, 2], prior=prior)
        for sid, m in ((1, m1), (2, m2)):
            for i in range(len(p)):
                z, R, H = place(sid, m[0][i:i + 1], m[1][i:i + 1], est.bias(sid))
                est.update(sid, H[0], 99, np.zeros((2, 3)), z[0] - p[i], 1e-6 * R[0])
        prior = {s: RadarBias(b.range_offset, b.range_gain, b.azimuth_deg, (500, 0.01, 0.5))
                 for s, b in est.biases().items()}
    for sid, t in ((1, t1), (2, t2)):
        b = est.bias(sid)
        assert b.range_offset == pytest.approx(t.range_offset, abs=1e-3)
        assert b.range_gain == pytest.approx(t.range_gain, abs=1e-8)
        assert b.azimuth_deg == pytest.approx(t.azimuth_deg, abs=1e-6)


def test_gate_rejects_a_wrong_pairing() -> None:
    """A pair 5 km apart (another aircraft) is gated out once the estimate has settled."""
    p = targets(100)
    meas = {1: measure(1, p, RadarBias(), None), 2: measure(2, p, RadarBias(), None)}
    est = BiasEstimator([2])
    one_pass(est, meas)
    before = est.b.copy()
    _, R2, H2 = place(2, *meas[2], est.bias(2))
    used = est.update(2, H2[0], 1, np.zeros((2, 3)), np.array([5e3, 0.0]), 2 * R2[0])
    assert not used and est.rejected == 1
    assert np.array_equal(est.b, before)


def test_reference_pairs_change_nothing() -> None:
    est = BiasEstimator([2])
    assert not est.update(1, np.ones((2, 3)), 3, np.ones((2, 3)), np.ones(2), np.eye(2))
    assert np.array_equal(est.b, np.zeros(3))


def _clustered_run(seed: int, true: RadarBias) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """30 aircraft, 6 pairs each; each aircraft's pairs share an error (radar 2 sees it
    60 m off, as a velocity error bridging its pairs would) that ``C`` leaves out. The
    error of (range offset, gain, azimuth) and its σ from the model ``P`` and the
    reported (cluster-robust) covariance."""
    rng = np.random.default_rng(seed)
    p = targets(30, seed)
    est = BiasEstimator([2])
    for g in range(len(p)):
        shared = rng.normal(0.0, 60.0, 2)
        for _ in range(6):
            r1, b1 = measure(1, p[g:g + 1], RadarBias(), rng)
            r2, b2 = measure(2, p[g:g + 1] + shared, true, rng)
            z2, R2, H2 = place(2, r2, b2, est.bias(2, model=True))
            z1, R1, H1 = place(1, r1, b1, est.bias(1))
            est.update(2, H2[0], 1, H1[0], z2[0] - z1[0], R1[0] + R2[0], cluster=g)
    b = est.bias(2)
    err = np.array([b.range_offset - true.range_offset, b.range_gain - true.range_gain,
                    b.azimuth_deg - true.azimuth_deg])
    return err, np.array(est.bias(2, model=True).sigma), np.array(b.sigma)


def test_cluster_robust_sigma_covers_shared_errors() -> None:
    """Errors shared within an aircraft's pairs: over 40 draws the model σ is optimistic
    (far fewer than 95 % of the errors within 2σ), the reported σ covers about 95 % of
    them (binomial: 40 draws × 3 components, expected 114 of 120)."""
    true = RadarBias(150.0, 0.9985, 0.09)
    runs = [_clustered_run(seed, true) for seed in range(40)]
    err = np.array([r[0] for r in runs])
    model = np.mean(np.abs(err) < 2 * np.array([r[1] for r in runs]))
    robust = np.mean(np.abs(err) < 2 * np.array([r[2] for r in runs]))
    assert model < 0.75
    assert 0.88 <= robust <= 1.0


def test_independent_pairs_robust_equals_model_on_average() -> None:
    """Independent pairs (each its own cluster) with the right ``C``: the reported
    variance is the model's on average (E[P_r] = P), within the sandwich's noise."""
    rng = np.random.default_rng(5)
    p = targets(200, 5)
    true = RadarBias(-80.0, 1.001, -0.05)
    meas = {1: measure(1, p, RadarBias(), rng), 2: measure(2, p, true, rng)}
    est = BiasEstimator([2])
    one_pass(est, meas)
    ratio = np.array(est.bias(2).sigma) / np.array(est.bias(2, model=True).sigma)
    assert np.all((ratio > 0.8) & (ratio < 1.25))
