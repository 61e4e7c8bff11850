"""The smoothed history (output ``smoothed``): the history's rows, each track smoothed by
the smoother over its own filtered rows (the former path: history with model states, then
:func:`mhtrack.models.smoother.smooth`); the online and history views unchanged."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mhtrack.models.smoother import Filtered, smooth
from mhtrack.pipeline import Pipeline, TrackOptions
from mhtrack.records import TrackTable
from mhtrack.scenario import preset, simulate
from mhtrack.scenario.overrides import apply_overrides
from mhtrack.sinks import TrackCollector
from mhtrack.sources.memory import MemorySource


@pytest.fixture(scope="module")
def scene():
    sc = apply_overrides(preset("opensky-radars"), scans=10)
    return sc, simulate(sc, seed=2)


def _run(scene, output: str, keep_models: bool = False) -> tuple[TrackTable, Pipeline]:
    sc, sim = scene
    pipe = Pipeline(MemorySource(sim.plots, sensors=sc.sensor_set()), TrackOptions(output=output))
    pipe.tracker.keep_models = keep_models
    rows = TrackCollector(output)
    pipe.run([rows])
    return rows.tracks(), pipe


def _columns(t: TrackTable, names: tuple[str, ...]) -> list[np.ndarray]:
    return [getattr(t, n) for n in names]


def test_smoothed_is_the_history_smoothed_track_by_track(scene) -> None:
    hist, _ = _run(scene, "history")
    kept, pipe = _run(scene, "history", keep_models=True)
    smoothed, _ = _run(scene, "smoothed")
    assert len(hist) > 50 and hist.tentative.any()
    # keeping the model states changes no filtered row
    for a, b in zip(_columns(hist, ("scan", "track_id", "x", "vx", "P", "tentative")),
                    _columns(kept, ("scan", "track_id", "x", "vx", "P", "tentative")),
                    strict=True):
        np.testing.assert_array_equal(a, b)
    assert kept.mu is not None and kept.mu.shape == (len(kept), pipe.tracker.motion.n_models)
    # the same rows, every column but the state the history's
    for name in ("scan", "time", "track_id", "plot", "score", "tentative"):
        np.testing.assert_array_equal(getattr(smoothed, name), getattr(hist, name))
    xs, Ps = smooth(Filtered(kept.track_id, kept.time,
                             np.column_stack((kept.x, kept.vx, kept.y, kept.vy)), kept.P,
                             kept.mu, kept.xm, kept.Pm), pipe.tracker.motion)
    np.testing.assert_array_equal(np.column_stack((smoothed.x, smoothed.vx, smoothed.y,
                                                   smoothed.vy)), xs)
    np.testing.assert_array_equal(smoothed.P, Ps)
    assert smoothed.mu is None  # model states stay in memory, never in the output
    # each track's last row is its filtered one; earlier rows moved
    last = np.r_[smoothed.track_id[np.lexsort((smoothed.time, smoothed.track_id))][1:]
                 != smoothed.track_id[np.lexsort((smoothed.time, smoothed.track_id))][:-1],
                 True]
    order = np.lexsort((smoothed.time, smoothed.track_id))
    np.testing.assert_array_equal(smoothed.x[order][last], hist.x[order][last])
    assert np.any(smoothed.x[order][~last] != hist.x[order][~last])


def test_backfilled_first_rows_get_a_velocity(scene) -> None:
    """A track's first row (a new tree's root: zero velocity) has, in the smoothed
    history, a velocity near its aircraft's true one (the truth row nearest in time and
    position): the velocity error well below the aircraft's speed (zero's error)."""
    truth = scene[1].truth
    hist, _ = _run(scene, "history")
    smoothed, _ = _run(scene, "smoothed")
    order = np.lexsort((hist.time, hist.track_id))
    first = np.r_[True, hist.track_id[order][1:] != hist.track_id[order][:-1]]
    rows = order[first]
    still = (hist.vx[rows] == 0) & (hist.vy[rows] == 0)
    assert still.any()  # the filtered history has them
    err, speed = [], []
    for i in rows[still]:
        near = np.abs(truth.time - hist.time[i]) <= 10.0
        j = near.nonzero()[0][np.argmin(np.hypot(truth.x[near] - hist.x[i],
                                                 truth.y[near] - hist.y[i]))]
        err.append(np.hypot(smoothed.vx[i] - truth.vx[j], smoothed.vy[i] - truth.vy[j]))
        speed.append(np.hypot(truth.vx[j], truth.vy[j]))
    assert np.median(np.array(err) / np.array(speed)) < 0.2


def test_online_view_unchanged(scene) -> None:
    online, _ = _run(scene, "online")
    smoothed, _ = _run(scene, "smoothed")
    hist, _ = _run(scene, "history")
    view = hist.online().sorted()
    assert len(smoothed.online()) == len(view)
    np.testing.assert_array_equal(online.sorted().x, view.x)
    # the online rows are those the smoothed history marks non-tentative
    np.testing.assert_array_equal(smoothed.online().scan, view.scan)
    np.testing.assert_array_equal(smoothed.online().track_id, view.track_id)


def test_smoothing_needs_covariances() -> None:
    from mhtrack.models.motion import ConstantVelocity
    from mhtrack.sinks.smoothed import smoothed_rows

    t = TrackTable(np.zeros(2, np.int64), np.array([0.0, 1.0]), np.zeros(2, np.int64),
                   np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2), np.full(2, -1))
    with pytest.raises(ValueError, match="covariance"):
        smoothed_rows(t, ConstantVelocity())
    empty = smoothed_rows(dataclasses.replace(TrackTable.empty()), ConstantVelocity())
    assert len(empty) == 0


def test_accuracy_follows_the_smoothed_covariance() -> None:
    """A row's σ major/minor/orientation (tracks that carry attributes) are those of its
    smoothed P; the other attributes are the row's own."""
    from mhtrack.attributes import TrackAttributes, accuracy
    from mhtrack.models.motion import ConstantVelocity
    from mhtrack.sinks.smoothed import smoothed_rows

    n = 5
    P = np.repeat(np.diag([400.0, 900.0, 100.0, 900.0])[None], n, axis=0)
    t = np.arange(n) * 4.0
    attrs = dataclasses.replace(TrackAttributes.absent(n, P),
                                callsign=np.array(["ABC"] * n, object))
    rows = TrackTable(np.arange(n), t, np.zeros(n, np.int64), 100.0 * t, 5.0 * t,
                      np.full(n, 100.0), np.full(n, 5.0), np.arange(n), P=P, attrs=attrs)
    out = smoothed_rows(rows, ConstantVelocity(2.0))
    assert out.attrs is not None and list(out.attrs.callsign) == ["ABC"] * n
    for got, want in zip((out.attrs.sigma_major, out.attrs.sigma_minor,
                          out.attrs.sigma_orient), accuracy(out.P), strict=True):
        np.testing.assert_array_equal(got, want)


def test_default_output_of_rotating_radars_is_smoothed(scene) -> None:
    """Timed plots of rotating radars (defaults from the radars): ``smoothed``; a
    scenario's scans (``run``): ``history``; an output given is kept."""
    sc, sim = scene
    src = MemorySource(sim.plots, sensors=sc.sensor_set())
    assert Pipeline(src, TrackOptions()).output == "smoothed"
    assert Pipeline(src, TrackOptions()).output_note is not None
    assert Pipeline(src, TrackOptions(output="history")).output == "history"
    assert Pipeline(src, TrackOptions(output="history")).output_note is None
    sc2 = apply_overrides(preset("crossing"), scans=3)
    sim2 = simulate(sc2, seed=1)
    assert Pipeline(MemorySource(sim2.plots, scenario=sc2), TrackOptions()).output == "history"


def test_other_sinks_see_each_frame_and_a_failure_leaves_no_file(scene, tmp_path) -> None:
    from mhtrack.sinks import CallbackSink, TracksFileSink

    sc, sim = scene
    pipe = Pipeline(MemorySource(sim.plots, sensors=sc.sensor_set()), TrackOptions())
    seen: list[int] = []
    rows = TrackCollector("smoothed")
    pipe.run([rows, CallbackSink(lambda out: seen.append(len(out.online)))])
    assert len(seen) > 100  # every frame, as reported
    assert sum(seen) == len(rows.tracks().online())

    pipe = Pipeline(MemorySource(sim.plots, sensors=sc.sensor_set()), TrackOptions())
    n = [0]

    def fail(_):
        n[0] += 1
        if n[0] == 50:
            raise OSError(5, "the recording went away")

    sink = TracksFileSink(tmp_path / "tracks.csv", frame=pipe.frame, output=pipe.output)
    with pytest.raises(OSError, match="went away"):
        pipe.run([sink, CallbackSink(fail)])
    assert list(tmp_path.iterdir()) == []
