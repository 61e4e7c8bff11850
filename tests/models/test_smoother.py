"""The fixed-interval smoother (mhtrack.models.smoother) against independent answers: the
batch least-squares (MAP) solution of a whole linear-Gaussian trajectory, solved with
NumPy's normal equations; an IMM of identical models against the one-model RTS; and, for
a manoeuvring target, smoothed errors below filtered ones over fixed seeds."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.models import kalman
from mhtrack.models.imm import CVModelSet, combine
from mhtrack.models.imm import update as imm_update
from mhtrack.models.motion import ConstantVelocity
from mhtrack.models.smoother import Filtered, smooth

H = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])
R = np.diag([30.0, 50.0]) ** 2
M0 = np.array([0.0, 100.0, 0.0, -50.0])
P0 = np.diag([100.0, 400.0, 100.0, 400.0])


def _kalman(t: np.ndarray, z: np.ndarray, cv: ConstantVelocity):
    """Filtered states of plots ``z`` at times ``t`` from the prior ``M0, P0``."""
    xs, Ps = [], []
    x, P = M0[None], P0[None]
    for k in range(len(t)):
        if k:
            dt = t[k] - t[k - 1]
            x, P = kalman.predict_cv(x, P, dt, cv.Q(dt))
        x, P = kalman.update_position(x, P, z[k][None], R)
        xs.append(x[0])
        Ps.append(P[0])
    return np.array(xs), np.array(Ps)


def _batch(t: np.ndarray, z: np.ndarray, sigma: float):
    """The MAP trajectory and its marginal covariances by normal equations over the
    unknowns ``u = (x_0, w_0 … w_{N−2})``: ``x_{k+1} = F x_k + G w_k``, ``w ~ N(0, σ² I)``
    (the discrete white-noise acceleration whose ``G Gᵀ σ²`` is ``Q``)."""
    n = len(t)
    m = 4 + 2 * (n - 1)
    phi = [np.zeros((4, m))]
    phi[0][:, :4] = np.eye(4)
    for k in range(n - 1):
        dt = t[k + 1] - t[k]
        F = np.kron(np.eye(2), [[1.0, dt], [0.0, 1.0]])
        G = np.array([[dt * dt / 2, 0], [dt, 0], [0, dt * dt / 2], [0, dt]])
        nxt = F @ phi[-1]
        nxt[:, 4 + 2 * k: 6 + 2 * k] += G
        phi.append(nxt)
    A = np.zeros((m, m))
    b = np.zeros(m)
    A[:4, :4] += np.linalg.inv(P0)
    b[:4] += np.linalg.inv(P0) @ M0
    A[4:, 4:] += np.eye(m - 4) / sigma**2
    Ri = np.linalg.inv(R)
    for k in range(n):
        J = H @ phi[k]
        A += J.T @ Ri @ J
        b += J.T @ Ri @ z[k]
    u = np.linalg.solve(A, b)
    C = np.linalg.inv(A)
    return np.array([p @ u for p in phi]), np.array([p @ C @ p.T for p in phi])


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(2, 15), st.floats(0.1, 20.0))
def test_rts_equals_batch_least_squares(seed: int, n: int, sigma: float) -> None:
    rng = np.random.default_rng(seed)
    t = np.r_[0.0, np.cumsum(rng.uniform(0.2, 12.0, n - 1))]  # irregular intervals
    z = rng.normal(size=(n, 2)) * 200.0 + 50.0 * t[:, None]
    cv = ConstantVelocity(sigma)
    x, P = _kalman(t, z, cv)
    xs, Ps = smooth(Filtered(np.zeros(n, np.int64), t, x, P), cv)
    want_x, want_P = _batch(t, z, sigma)
    scale = np.abs(want_x).max()
    np.testing.assert_allclose(xs, want_x, atol=1e-7 * scale, rtol=0)
    np.testing.assert_allclose(Ps, want_P, atol=1e-7 * np.abs(want_P).max(), rtol=0)
    # the last row is the filtered estimate
    np.testing.assert_array_equal(xs[-1], x[-1])


def test_tracks_smoothed_together_as_each_alone() -> None:
    """Rows of several tracks, shuffled: each track's rows as if smoothed alone."""
    rng = np.random.default_rng(4)
    cv = ConstantVelocity(3.0)
    parts = []
    for tid, n in ((7, 9), (2, 1), (5, 14)):
        t = 100.0 * tid + np.r_[0.0, np.cumsum(rng.uniform(1, 6, n - 1))]
        z = rng.normal(size=(n, 2)) * 100.0
        x, P = _kalman(t, z, cv)
        parts.append((np.full(n, tid), t, x, P, *smooth(Filtered(np.full(n, tid), t, x, P), cv)))
    cat = [np.concatenate([p[i] for p in parts]) for i in range(6)]
    perm = rng.permutation(len(cat[0]))
    xs, Ps = smooth(Filtered(*(c[perm] for c in cat[:4])), cv)
    np.testing.assert_allclose(xs, cat[4][perm], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(Ps, cat[5][perm], rtol=1e-12, atol=1e-9)


def _imm_filter(model: CVModelSet, t: np.ndarray, z: np.ndarray):
    """The IMM of :mod:`mhtrack.models.imm` over plots ``z``: per row, its filtered model
    states and probabilities."""
    r = model.r
    st_ = model.new_states(M0[None], P0[None])
    xm, Pm, mu = st_.xm, st_.Pm, st_.mu
    out = []
    for k in range(len(t)):
        if k:
            xm, Pm, mu = model.predict_models(xm, Pm, mu, t[k] - t[k - 1])
        xm, Pm, mu = imm_update(xm, Pm, mu, z[k][None], R)
        out.append((xm[0], Pm[0], mu[0]))
    xm, Pm, mu = (np.array([o[i] for o in out]) for i in range(3))
    x, P = combine(xm, Pm, mu)
    assert xm.shape[1] == r
    return x, P, mu, xm, Pm


def test_imm_of_identical_models_is_the_rts() -> None:
    """Two models with one σ: Kim's smoother reduces to the RTS of that model."""
    rng = np.random.default_rng(11)
    n = 12
    t = np.r_[0.0, np.cumsum(rng.uniform(1, 10, n - 1))]
    z = rng.normal(size=(n, 2)) * 150.0
    x, P, mu, xm, Pm = _imm_filter(CVModelSet((4.0, 4.0)), t, z)
    ids = np.zeros(n, np.int64)
    got = smooth(Filtered(ids, t, x, P, mu, xm, Pm), CVModelSet((4.0, 4.0)))
    want = smooth(Filtered(ids, t, *_kalman(t, z, ConstantVelocity(4.0))),
                  ConstantVelocity(4.0))
    np.testing.assert_allclose(got[0], want[0], rtol=0, atol=1e-6)
    np.testing.assert_allclose(got[1], want[1], rtol=1e-8, atol=1e-6)


def _manoeuvre(rng: np.random.Generator, n: int = 80):
    """A target flying straight, turning at 3°/s for 30 s, straight again; plots every
    4–12 s (irregular: several radars), noise ``R``."""
    dt = rng.uniform(4.0, 12.0, n - 1)
    t = np.r_[0.0, np.cumsum(dt)]
    truth = np.zeros((n, 4))
    pos, vel = np.zeros(2), np.array([200.0, 0.0])
    t_turn = t[n // 3]
    truth[0] = [pos[0], vel[0], pos[1], vel[1]]
    for k in range(1, n):  # integrate in 0.5 s steps
        tt = t[k - 1]
        while tt < t[k] - 1e-9:
            h = min(0.5, t[k] - tt)
            w = np.radians(3.0) if t_turn <= tt < t_turn + 30.0 else 0.0
            c, s = np.cos(w * h), np.sin(w * h)
            pos = pos + vel * h
            vel = np.array([c * vel[0] - s * vel[1], s * vel[0] + c * vel[1]])
            tt += h
        truth[k] = [pos[0], vel[0], pos[1], vel[1]]
    z = truth[:, [0, 2]] + rng.multivariate_normal(np.zeros(2), R, n)
    return t, z, truth


def test_imm_smoothed_error_below_filtered_over_seeds() -> None:
    model = CVModelSet((1.0, 10.0), mode_time=100.0)
    f_pos = s_pos = f_vel = s_vel = 0.0
    for seed in range(10):
        rng = np.random.default_rng(seed)
        t, z, truth = _manoeuvre(rng)
        x, P, mu, xm, Pm = _imm_filter(model, t, z)
        xs, _ = smooth(Filtered(np.zeros(len(t), np.int64), t, x, P, mu, xm, Pm), model)
        sl = slice(3, None)  # after the first plots' start-up
        f_pos += np.mean(np.sum((x - truth)[sl][:, [0, 2]] ** 2, axis=1))
        s_pos += np.mean(np.sum((xs - truth)[sl][:, [0, 2]] ** 2, axis=1))
        f_vel += np.mean(np.sum((x - truth)[sl][:, [1, 3]] ** 2, axis=1))
        s_vel += np.mean(np.sum((xs - truth)[sl][:, [1, 3]] ** 2, axis=1))
    assert s_pos < 0.8 * f_pos
    assert s_vel < 0.8 * f_vel


def test_imm_needs_the_model_states() -> None:
    t = np.array([0.0, 1.0])
    with pytest.raises(ValueError, match="model states"):
        smooth(Filtered(np.zeros(2, np.int64), t, np.zeros((2, 4)),
                        np.repeat(np.eye(4)[None], 2, axis=0)), CVModelSet((1.0, 10.0)))


def test_first_row_of_zero_velocity_gets_the_tracks_velocity() -> None:
    """A track started from one plot (velocity 0, wide velocity variance, as a new tree):
    its first smoothed row has the velocity the later plots show."""
    cv = ConstantVelocity(1.0)
    t = np.arange(6) * 5.0
    z = np.column_stack((150.0 * t, -80.0 * t))
    x, P = [], []
    xk, Pk = np.zeros((1, 4)), np.diag([R[0, 0], 300.0**2, R[1, 1], 300.0**2])[None]
    for k in range(len(t)):
        if k:
            xk, Pk = kalman.predict_cv(xk, Pk, 5.0, cv.Q(5.0))
            xk, Pk = kalman.update_position(xk, Pk, z[k][None], R)
        x.append(xk[0])
        P.append(Pk[0])
    x, P = np.array(x), np.array(P)
    assert x[0, 1] == 0.0
    xs, _ = smooth(Filtered(np.zeros(len(t), np.int64), t, x, P), cv)
    np.testing.assert_allclose(xs[0, [1, 3]], [150.0, -80.0], rtol=0.05)


def test_rts_equals_stone_soups_kalman_smoother() -> None:
    """Stone Soup's own filter (KalmanPredictor, KalmanUpdater) and KalmanSmoother on the
    same plots, with mhtrack's F(dt) and Q(dt) as its transition model."""
    pytest.importorskip("stonesoup")
    import datetime

    from stonesoup.base import Property
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import LinearGaussianTransitionModel
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.smoother.kalman import KalmanSmoother
    from stonesoup.types.detection import Detection
    from stonesoup.types.hypothesis import SingleHypothesis
    from stonesoup.types.state import GaussianState
    from stonesoup.types.track import Track
    from stonesoup.updater.kalman import KalmanUpdater

    class DiscreteCV(LinearGaussianTransitionModel):
        sigma: float = Property(doc="acceleration noise std (m/s²)")

        @property
        def ndim_state(self) -> int:
            return 4

        def matrix(self, time_interval: datetime.timedelta, **kwargs) -> np.ndarray:
            return ConstantVelocity.F(time_interval.total_seconds())

        def covar(self, time_interval: datetime.timedelta, **kwargs) -> np.ndarray:
            return ConstantVelocity(self.sigma).Q(time_interval.total_seconds())

    rng = np.random.default_rng(5)
    n, sigma = 15, 3.0
    # whole microseconds: Stone Soup's times are datetimes
    t = np.round(np.r_[0.0, np.cumsum(rng.uniform(0.5, 10.0, n - 1))], 6)
    z = rng.normal(size=(n, 2)) * 150.0 + 80.0 * t[:, None]
    t0 = datetime.datetime(2024, 1, 1)
    model = DiscreteCV(sigma=sigma)
    predictor = KalmanPredictor(model)
    updater = KalmanUpdater(LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=R))
    prior = GaussianState(M0.reshape(4, 1), P0, timestamp=t0)
    track = Track()
    for k in range(n):
        when = t0 + datetime.timedelta(seconds=float(t[k]))
        pred = predictor.predict(prior, timestamp=when)
        det = Detection(z[k].reshape(2, 1), timestamp=when,
                        measurement_model=updater.measurement_model)
        prior = updater.update(SingleHypothesis(pred, det))
        track.append(prior)
    want = KalmanSmoother(transition_model=model).smooth(track)
    x = np.array([s.state_vector.ravel() for s in track], float)
    P = np.array([s.covar for s in track], float)
    xs, Ps = smooth(Filtered(np.zeros(n, np.int64), t, x, P), ConstantVelocity(sigma))
    np.testing.assert_allclose(xs, np.array([s.state_vector.ravel() for s in want], float),
                               rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(Ps, np.array([s.covar for s in want], float),
                               rtol=1e-7, atol=1e-6)
