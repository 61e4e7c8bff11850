"""Tracks that say what they are (issue 29 item 5): the reported tracks' flight level and
rate of climb, code, address, callsign and accuracy, checked against the scenario that
made the plots, NumPy's eigen-decomposition and a save/restore."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.attributes import PlotAttributes, TrackAttributes, accuracy, existence
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.tracker import MHTTracker
from mhtrack.records import Scan, TrackTable


@settings(max_examples=200, deadline=None)
@given(st.floats(1.0, 1e6), st.floats(1.0, 1e6), st.floats(-0.99, 0.99))
def test_accuracy_is_the_eigen_decomposition(sx, sy, rho):
    P = np.zeros((1, 4, 4))
    P[0, 0, 0], P[0, 2, 2] = sx * sx, sy * sy
    P[0, 0, 2] = P[0, 2, 0] = rho * sx * sy
    major, minor, orient = accuracy(P)
    w, v = np.linalg.eigh(P[0][np.ix_([0, 2], [0, 2])])
    np.testing.assert_allclose([minor[0] ** 2, major[0] ** 2], w, rtol=1e-6,
                               atol=1e-9 * w[1])
    assert 0.0 <= orient[0] < 180.0
    axis = np.array([np.sin(np.radians(orient[0])), np.cos(np.radians(orient[0]))])
    if w[1] - w[0] > 1e-6 * w[1]:  # a circle has no major axis
        assert abs(abs(axis @ v[:, 1]) - 1.0) < 1e-6


def test_accuracy_of_axis_aligned_ellipses_by_hand():
    P = np.zeros((2, 4, 4))
    P[0, 0, 0], P[0, 2, 2] = 400.0, 100.0  # wider east-west: major axis bearing 90°
    P[1, 0, 0], P[1, 2, 2] = 100.0, 400.0  # north-south: bearing 0°
    major, minor, orient = accuracy(P)
    np.testing.assert_allclose(major, [20.0, 20.0])
    np.testing.assert_allclose(minor, [10.0, 10.0])
    np.testing.assert_allclose(orient, [90.0, 0.0])


def _climber(n=40, rate_fl_s=0.25, callsign_every=5, drop=(), past=False, config=None,
             primary=False):
    """One aircraft east at 200 m/s climbing from FL 200 at ``rate_fl_s``, replying
    code 4321 and address 0x3C4591 on every plot, its callsign BOX413 only on every
    ``callsign_every``-th; no clutter; scans ``drop`` without a plot. ``past``: the
    rows of the track's tentative past (the history output) too. ``primary``: primary
    plots instead (no reply: a type and nothing else)."""
    rng = np.random.default_rng(3)
    trk, outs = MHTTracker(config), []
    row = 0
    for k in range(n):
        if k in drop:
            z = np.zeros((0, 2))
            attrs = PlotAttributes.absent(0)
        else:
            z = np.array([[200.0 * k, 0.0]]) + rng.normal(scale=50.0, size=(1, 2))
            attrs = PlotAttributes.from_columns({"plot_type": np.array([1])}, 1) \
                if primary else PlotAttributes.from_columns({
                "flight_level": np.array([200.0 + rate_fl_s * k]),
                "mode_3a": np.array([0o4321]), "address": np.array([0x3C4591]),
                "callsign": np.array(["BOX413" if k % callsign_every == 0 else ""],
                                     object)}, 1)
        m = len(z)
        outs.append(trk.step(Scan(k, float(k), z, np.zeros(m, np.int64),
                                  np.arange(row, row + m), attrs=attrs)))
        if past:
            outs.append(trk.last_backfill)
        row += m
    return trk, TrackTable.concat(outs)


def test_a_climbing_track_reports_its_level_rate_code_address_and_callsign():
    _, tt = _climber()
    assert len(tt) > 20 and tt.attrs is not None and np.unique(tt.track_id).size == 1
    a = tt.attrs
    late = tt.scan >= 15  # the vertical filter has settled
    truth = 200.0 + 0.25 * tt.time
    assert np.abs(a.flight_level[late] - truth[late]).max() < 0.5  # σ_C 0.5 FL
    np.testing.assert_allclose(a.rate_of_climb[late], 0.25 * 6000.0, rtol=0.1)
    assert set(a.mode_3a.tolist()) == {0o4321}
    assert set(a.address.tolist()) == {0x3C4591}
    # the callsign of a plot every 5 scans, carried on the rows between (from the
    # first one reported: scan 0's plot was the tentative track's)
    assert set(a.callsign[tt.scan >= 5].tolist()) == {"BOX413"}
    assert set(a.callsign[tt.scan < 5].tolist()) <= {""}
    major, minor, _ = accuracy(tt.P)
    np.testing.assert_array_equal(a.sigma_major, major)
    np.testing.assert_array_equal(a.sigma_minor, minor)


def test_existence_probability_by_hand():
    # P = 1/(1 + e^-L): L = 0 even odds, ln 3 three to one, -ln 9 one to nine
    L = np.array([0.0, np.log(3.0), -np.log(9.0), 800.0, -800.0])
    np.testing.assert_allclose(existence(L), [0.5, 0.75, 0.1, 1.0, 0.0], atol=1e-15)


def test_every_row_and_its_tentative_past_carry_the_existence_of_its_score():
    _, tt = _climber(n=20, past=True)
    back = tt.tentative.astype(bool)
    assert back.any() and (~back).any()  # the history output: both kinds of rows
    p = tt.attrs.existence_probability
    np.testing.assert_allclose(p, 1.0 / (1.0 + np.exp(-tt.score)), rtol=1e-12)
    assert np.all((p > 0) & (p <= 1))


def test_the_tentative_past_says_what_its_plots_measured():
    """The backfilled rows (scans before confirmation) carry their own plot's sensor,
    code and level as the scenario made them, the callsign of scan 0's plot and the
    sensor that updated them, as the confirmed rows do."""
    slow = MHTConfig(alpha=1e-9)  # an SPRT that waits for more plots: a longer past
    _, tt = _climber(n=20, drop=(2,), past=True, config=slow)
    back = tt.tentative.astype(bool)
    a = tt.attrs
    hit = back & (tt.plot >= 0)
    assert hit.sum() >= 2 and (back & (tt.plot < 0)).any()  # scan 2: a miss
    assert (a.meas_sensor[hit] == 0).all() and (a.meas_mode_3a[hit] == 0o4321).all()
    np.testing.assert_array_equal(a.meas_flight_level[hit], 200.0 + 0.25 * tt.scan[hit])
    assert (a.meas_sensor[back & (tt.plot < 0)] == -1).all()
    assert set(a.callsign[back].tolist()) == {"BOX413"}  # scan 0's plot carried it
    assert set(a.sensors[back].tolist()) == {"0"}
    ages = np.array([float(v) for v in a.sensor_ages[back].tolist()])
    np.testing.assert_allclose(ages, np.where(tt.plot[back] >= 0, 0.0, 1.0))  # 1 s scans


def test_a_primary_track_past_says_what_its_plots_measured():
    """A primary-only aircraft (no identity on any tentative leaf) starting while one
    that replied until scan 10 (its track keeps the identity) is tracked 50 km away:
    its backfilled rows still carry their plot's sensor and type, and the existence
    probability of their score, as its online rows."""
    rng = np.random.default_rng(4)
    trk, outs, row = MHTTracker(MHTConfig(alpha=1e-9)), [], 0
    for k in range(34):
        z = [[200.0 * k, 0.0]] + ([[200.0 * k, 50_000.0]] if k >= 20 else [])
        z = np.array(z) + rng.normal(scale=50.0, size=(len(z), 2))
        m = len(z)
        attrs = PlotAttributes.from_columns({
            "plot_type": np.array([4 if k < 10 else 1, 1][:m]),
            "mode_3a": np.array([0o4321 if k < 10 else -1, -1][:m]),
            "address": np.array([0x3C4591 if k < 10 else -1, -1][:m]),
            "flight_level": np.array([200.0 if k < 10 else np.nan, np.nan][:m])}, m)
        outs.append(trk.step(Scan(k, float(k), z, np.zeros(m, np.int64),
                                  np.arange(row, row + m), attrs=attrs)))
        outs.append(trk.last_backfill)
        row += m
    tt = TrackTable.concat(outs)
    a = tt.attrs
    primary = np.isin(tt.track_id, tt.track_id[(a.address < 0) & (tt.scan >= 25)])
    back = tt.tentative.astype(bool) & primary
    hit = back & (tt.plot >= 0)
    assert hit.sum() >= 2
    assert (a.meas_sensor[hit] == 0).all() and (a.meas_type[hit] == 1).all()
    assert (a.mode_3a[back] == -1).all() and np.isnan(a.flight_level[back]).all()
    np.testing.assert_allclose(a.existence_probability, 1.0 / (1.0 + np.exp(-tt.score)),
                               rtol=1e-12)


def test_a_miss_reports_the_predicted_level():
    _, tt = _climber(drop=(25,))
    row = (tt.scan == 25).nonzero()[0]
    assert row.size == 1 and tt.plot[row[0]] < 0
    np.testing.assert_allclose(tt.attrs.flight_level[row[0]], 200.0 + 0.25 * 25, atol=0.5)


def test_without_attributes_a_track_has_none():
    rng = np.random.default_rng(3)
    trk, outs = MHTTracker(), []
    for k in range(15):
        z = np.array([[200.0 * k, 0.0]]) + rng.normal(scale=50.0, size=(1, 2))
        outs.append(trk.step(Scan(k, float(k), z, np.zeros(1, np.int64),
                                  np.arange(k, k + 1))))
    tt = TrackTable.concat(outs)
    assert len(tt) and tt.attrs is None


def test_tentative_past_has_accuracy_but_no_identity():
    """Rows of a track's tentative past (the history output) carry σ from their own
    covariance, absent attributes; concatenated with online rows that have them."""
    _, online = _climber(n=12)
    past = TrackTable(np.array([0]), np.array([0.0]), np.array([0]), np.zeros(1),
                      np.zeros(1), np.zeros(1), np.zeros(1), np.array([-1]),
                      P=np.diag([9.0, 1.0, 4.0, 1.0])[None], tentative=np.ones(1, bool))
    both = TrackTable.concat([past, online])
    assert both.attrs.mode_3a[0] == -1 and np.isnan(both.attrs.flight_level[0])
    np.testing.assert_allclose([both.attrs.sigma_major[0], both.attrs.sigma_minor[0],
                                both.attrs.sigma_orient[0]], [3.0, 2.0, 90.0])
    assert both.attrs[1:].mode_3a.tolist() == online.attrs.mode_3a.tolist()
    assert isinstance(both.take(np.array([1])).attrs, TrackAttributes)


def test_save_restore_keeps_the_callsigns(tmp_path):
    _, tt = _climber(n=30, callsign_every=10)
    assert set(tt.attrs.callsign[tt.scan >= 10].tolist()) == {"BOX413"}
    rng = np.random.default_rng(3)
    first = MHTTracker()
    for k in range(20):
        z = np.array([[200.0 * k, 0.0]]) + rng.normal(scale=50.0, size=(1, 2))
        attrs = PlotAttributes.from_columns({
            "flight_level": np.array([200.0 + 0.25 * k]), "mode_3a": np.array([0o4321]),
            "address": np.array([0x3C4591]),
            "callsign": np.array(["BOX413" if k == 10 else ""], object)}, 1)
        first.step(Scan(k, float(k), z, np.zeros(1, np.int64), np.arange(k, k + 1),
                        attrs=attrs))
    first.save(tmp_path / "s.npz")
    again = MHTTracker.load(tmp_path / "s.npz")
    z = np.array([[200.0 * 20, 0.0]])
    out = again.step(Scan(20, 20.0, z, np.zeros(1, np.int64), np.arange(20, 21),
                          attrs=PlotAttributes.from_columns(
                              {"address": np.array([0x3C4591])}, 1)))
    assert out.attrs.callsign.tolist() == ["BOX413"]


def test_sensors_and_their_ages_by_hand():
    """One aircraft seen by sensor 1 at even scans and sensor 2 at scans 0-19 (odd),
    1 s apart: each row names the sensors that updated the track and how long ago."""
    rng = np.random.default_rng(8)
    trk, outs = MHTTracker(), []
    row = 0
    for k in range(30):
        sensor = 1 if k % 2 == 0 else 2
        if sensor == 2 and k >= 20:
            z = np.zeros((0, 2))
        else:
            z = np.array([[200.0 * k, 0.0]]) + rng.normal(scale=30.0, size=(1, 2))
        m = len(z)
        attrs = PlotAttributes.from_columns({"address": np.full(m, 0xABC)}, m)
        outs.append(trk.step(Scan(k, float(k), z, np.full(m, sensor, np.int64),
                                  np.arange(row, row + m), attrs=attrs)))
        row += m
    tt = TrackTable.concat(outs)
    assert np.unique(tt.track_id).size == 1
    a = tt.attrs
    for k, s, ages in zip(tt.scan.tolist(), a.sensors.tolist(), a.sensor_ages.tolist(),
                          strict=True):
        if k < 4:
            continue  # confirmation: the first rows may name one sensor only
        assert s == "1;2", (k, s)
        age1, age2 = (float(v) for v in ages.split(";"))
        assert age1 == k % 2  # sensor 1 updated at the last even scan
        assert age2 == (k - 19 if k >= 20 else (k + 1) % 2)
