"""Checkpoints and restart of a live run (:mod:`mhtrack.pipeline.checkpoint`): stopped
midway with a checkpoint and resumed on the rest of the datagrams, the combined output
equals that of a run never stopped — row for row, the same frame numbers and track ids
— on update and on a period; periodic checkpoints are written on data time and load.

The runs read stdin (a pipe): deterministic, bounded by counts (the stop is set once the
reader has received the first part's datagrams)."""

from __future__ import annotations

import io
import json
import os
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from sim_recording import simulated_recording  # tests/helpers

from mhtrack.errors import InputError
from mhtrack.io.sensors import read_sensors
from mhtrack.pipeline import TrackOptions
from mhtrack.pipeline.checkpoint import CheckpointSink, read_checkpoint
from mhtrack.pipeline.live import Live, LiveOptions
from mhtrack.sources.replay import recording_datagrams

OPTIONS = TrackOptions(output="online", new_target_density=1e-10)


@pytest.fixture(scope="module")
def rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(tmp_path_factory.mktemp("ckpt"), seed=1, scans=6)


def _blocks(rec: Path) -> list[bytes]:
    return [d if isinstance(d, bytes) else d[0] for d in recording_datagrams(rec / "radar.ast")]


def _run(rec: Path, blocks: list[bytes], stop_after: int | None = None,
         track: TrackOptions = OPTIONS, **options: object) -> tuple[list[dict], Live]:
    """A live run over stdin on ``blocks`` (JSON lines): to the end of the input, or
    stopped (as by SIGTERM) once ``stop_after`` datagrams were received."""
    r, w = os.pipe()
    stop = threading.Event()
    out = io.StringIO()
    with os.fdopen(r, "rb", buffering=0) as rf:
        live = Live(read_sensors(rec / "sensors.toml"), track,
                    LiveOptions(preload=False,
                                stdin="raw", day_from="stream", json=True, **options),
                    stdin=rf, stdout=out, stop=stop)

        def feed() -> None:
            os.write(w, b"".join(blocks))
            if stop_after is not None:
                while live.reader.stats.datagrams < stop_after and not stop.is_set():
                    time.sleep(0.005)  # bounded by the count: the pipe holds them all
                stop.set()
            os.close(w)

        feeder = threading.Thread(target=feed)
        feeder.start()
        try:
            live.run()
        finally:
            stop.set()
            feeder.join()
    return [json.loads(x) for x in out.getvalue().splitlines()], live


@pytest.mark.parametrize("period", [None, 4.0])
@pytest.mark.parametrize("cut", [0.3, 0.55])
def test_stop_and_resume_equals_one_run(rec: Path, tmp_path: Path, period: float | None,
                                        cut: float) -> None:
    blocks = _blocks(rec)
    k = int(cut * len(blocks))
    whole, _ = _run(rec, blocks, period_out_s=period)
    ck = tmp_path / "state.npz"
    first, one = _run(rec, blocks[:k], stop_after=k, checkpoint=ck, period_out_s=period)
    assert one.checkpoints is not None and one.checkpoints.written == 1  # the final one
    held = one.source.held
    assert held is not None and held["framed"] is not None  # plots were waiting
    second, two = _run(rec, blocks[k:], checkpoint=ck, resume=True, period_out_s=period)
    assert two.resumed is not None and two.resumed.next_frame == one.source.next_frame
    assert len(first) > 0 and len(second) > 0
    assert first + second == whole  # every row: frame (tick), time, id, state
    ids_before = {r["track_id"] for r in first}
    assert ids_before & {r["track_id"] for r in second}  # tracks go on with their ids
    assert two.source.stats.late_dropped == 0


@pytest.mark.parametrize("cut", [0.3, 0.45])
def test_stop_and_resume_with_sector_frames(rec: Path, tmp_path: Path, cut: float) -> None:
    """``--sector-frames``: the checkpoint keeps the crossings held and each radar's count
    of crossings (a plot's sector), so the resumed run cuts and closes the frames of the
    run never stopped (before, reading it back failed on a held crossing's blank callsign,
    and the sectors numbered from 0 again cut other frames); the resumed run's crossings
    are counted as such, none as a late plot."""
    blocks = _blocks(rec)
    k = int(cut * len(blocks))
    whole, w = _run(rec, blocks, sectors=True)
    ck = tmp_path / "state.npz"
    first, one = _run(rec, blocks[:k], stop_after=k, checkpoint=ck, sectors=True)
    held = one.source.held
    assert held is not None and held["held"] is not None and held["held"]["mark"].any()
    second, two = _run(rec, blocks[k:], checkpoint=ck, resume=True, sectors=True)
    assert len(first) > 0 and len(second) > 0 and first + second == whole
    assert two.source.stats.late_dropped == two.source.stats.late_crossings == 0
    frames = one.health.frames + two.health.frames
    assert frames == w.health.frames
    lat = two.health.snapshot()["latency_s"]
    assert lat["by_crossing"] > 0  # the resumed run's sectors timed by their crossings


def test_sector_frames_must_match_the_checkpoint(rec: Path, tmp_path: Path) -> None:
    """``--sector-frames`` is kept with the checkpoint's options: a resume that toggles
    it is refused in one line before any datagram is read (on → off, a crossing held
    reached the tracker as a plot of NaN; off → on, a traceback in the framer); a
    checkpoint of the previous mhtrack (no counts of crossings, no such option) holding
    plots with their sectors is refused naming the field."""
    blocks = _blocks(rec)
    k = int(0.3 * len(blocks))
    sensors = read_sensors(rec / "sensors.toml")

    def resume(ck: Path, sectors: bool) -> Live:
        return Live(sensors, OPTIONS, LiveOptions(preload=False, stdin="raw", checkpoint=ck,
                                                  resume=True, sectors=sectors),
                    stdin=io.BytesIO(b""))

    for sectors in (True, False):
        ck = tmp_path / f"state-{sectors}.npz"
        _run(rec, blocks[:k], stop_after=k, checkpoint=ck, sectors=sectors)
        with pytest.raises(InputError) as e:
            resume(ck, not sectors)
        assert str(e.value) == (
            f"{ck}: written with other tracking options (sector_frames {sectors} there, "
            f"{not sectors} here): resume with the same options, or start afresh "
            "without --resume")
        assert resume(ck, sectors).resumed is not None
    tracker, state = read_checkpoint(tmp_path / "state-True.npz")
    assert state.pending is not None and "sector" in state.pending["held"]
    assert state.options is not None and state.options["sector_frames"] is True
    old = tmp_path / "old.npz"  # as the previous mhtrack wrote it
    CheckpointSink(old, lambda: tracker, lambda: replace(
        state, pending={k: v for k, v in state.pending.items() if k != "marks"},
        options={k: v for k, v in state.options.items() if k != "sector_frames"})).save()
    with pytest.raises(InputError) as e:
        resume(old, True)
    assert str(e.value) == (
        f"{old}: member 'meta': field 'extra': pending: plots held with their sectors but "
        "no 'marks' (each radar's count of sector crossings): written before sector "
        "counts were kept: start afresh without --resume")


def test_a_copy_late_across_the_restart_is_a_copy(rec: Path, tmp_path: Path) -> None:
    """Redundant LANs: copies of the last blocks received before the stop arrive after
    the restart (the second LAN behind). The checkpoint keeps the duplicate filter's
    blocks, so the resumed run drops them as copies — its rows are those of the one run
    on the stream without them, and it tracks as many plots — where a fresh filter
    tracks their plots twice."""
    blocks = _blocks(rec)
    k = len(blocks) // 2
    whole, one = _run(rec, blocks)
    ck = tmp_path / "state.npz"
    first, cut = _run(rec, blocks[:k], stop_after=k, checkpoint=ck)
    tracker, state = read_checkpoint(ck)
    assert state.duplicates is not None and len(state.duplicates) == 40 * k  # k < 4 096
    # the same checkpoint without the filter's blocks (as before they were kept)
    blind = tmp_path / "blind.npz"
    CheckpointSink(blind, lambda: tracker, lambda: replace(state, duplicates=None)).save()
    late = blocks[k - 3:k]  # the second LAN's copies, after the restart
    second, two = _run(rec, late + blocks[k:], checkpoint=ck, resume=True)
    assert two.source.problems.counts.get("duplicate", 0) == len(late)
    assert first + second == whole
    _, three = _run(rec, late + blocks[k:], checkpoint=blind, resume=True)
    assert three.source.problems.counts.get("duplicate", 0) == 0  # taken twice
    tracked = one.source.stats.plots_out
    assert cut.source.stats.plots_out + two.source.stats.plots_out == tracked
    extra = three.source.stats.plots_in - two.source.stats.plots_in
    assert extra > 0 and cut.source.stats.plots_out + three.source.stats.plots_out == \
        tracked + extra  # (the rows may hide it: a plot twice in a frame is clutter)


def test_without_a_checkpoint_a_stop_tracks_what_it_holds(rec: Path) -> None:
    blocks = _blocks(rec)
    k = len(blocks) // 2
    rows, live = _run(rec, blocks[:k], stop_after=k)
    ref, _ = _run(rec, blocks[:k])  # the end of the input: every frame made
    assert live.source.held is None and rows == ref


def test_periodic_checkpoints_on_data_time(rec: Path, tmp_path: Path) -> None:
    ck = tmp_path / "state.npz"
    rows, live = _run(rec, _blocks(rec), checkpoint=ck, checkpoint_every_s=20.0)
    times = [r["time"] for r in rows]
    span = max(times) - min(times)
    # one on every frame 20 s of data after the last (the first frame starts the clock),
    # and the final one
    assert live.checkpoints is not None
    assert int(span // 20) <= live.checkpoints.written - 1 <= int(span // 20) + 1
    tracker, state = read_checkpoint(ck)
    assert state.pending is None  # the input ended: everything tracked
    assert state.next_frame == live.source.next_frame
    assert tracker.last_time == live.pipeline.tracker.last_time >= max(times)


def test_resume_needs_a_checkpoint_file(rec: Path, tmp_path: Path) -> None:
    sensors = read_sensors(rec / "sensors.toml")
    with pytest.raises(ValueError, match="--checkpoint"):
        Live(sensors, OPTIONS, LiveOptions(preload=False, stdin="raw", resume=True))
    # --resume without the file yet: a fresh start (the first start of a service)
    live = Live(sensors, OPTIONS, LiveOptions(preload=False, stdin="raw", resume=True,
                                              checkpoint=tmp_path / "none.npz"),
                stdin=io.BytesIO(b""))
    assert live.resumed is None


def test_held_plots_keep_their_columns_types_through_json() -> None:
    """The plots a checkpoint holds come back with each column's type — text attribute
    columns (callsign, an object array of str) included; a column of any other object
    is refused (a checkpoint is read from disk, so it may be hostile)."""
    import json

    import numpy as np
    import pytest

    from mhtrack.pipeline.checkpoint import decode_pending, encode_pending

    callsign = np.empty(2, object)
    callsign[:] = ["AFR12", ""]
    held = {"time": np.array([1.5, 0.1 + 0.2]), "sensor": np.array([3, 4]),
            "callsign": callsign, "mode_3a_v": np.array([0, 1], np.int8),
            "file_row": np.array([7, 8])}
    saved = json.loads(json.dumps(encode_pending(
        {"latest": 2.0, "released": -np.inf, "framed": None, "held": held})))
    back = decode_pending(saved)["held"]
    assert back["time"].tolist() == held["time"].tolist()  # to the bit
    assert back["sensor"].dtype == held["sensor"].dtype
    assert back["mode_3a_v"].dtype == np.int8
    assert back["callsign"].dtype == object and back["callsign"].tolist() == ["AFR12", ""]
    assert back["file_row"].tolist() == [-1, -1]  # numbers of the earlier run
    saved["held"]["callsign"]["values"] = [{"a": 1}, ""]
    with pytest.raises(ValueError, match="numbers or text only"):
        decode_pending(saved)


BIAS = TrackOptions(output="online", new_target_density=1e-10, estimate_bias=True,
                    bias_reference=3)


@pytest.fixture(scope="module")
def biased(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_recording(tmp_path_factory.mktemp("bias"), seed=2, scans=12,
                               simulate=("--bias", "1:range=200,azimuth=-0.12",
                                         "--bias", "2:gain=1.002,azimuth=0.08"))


def test_bias_state_goes_through_the_checkpoint(biased: Path, tmp_path: Path) -> None:
    """With --estimate-bias, a run stopped midway and resumed from its checkpoint gives
    the rows and the final bias estimate (every float) of a run never stopped: the
    checkpoint holds the estimator's state, its robust sums and the tracks' last plots."""
    blocks = _blocks(biased)
    k = len(blocks) // 2
    whole, w = _run(biased, blocks, track=BIAS)
    ck = tmp_path / "state.npz"
    first, _ = _run(biased, blocks[:k], stop_after=k, track=BIAS, checkpoint=ck)
    _, state = read_checkpoint(ck)
    assert state.bias is not None and state.bias["pairs"] > 0  # pairs learnt before
    second, two = _run(biased, blocks[k:], track=BIAS, checkpoint=ck, resume=True)
    assert first + second == whole
    reg_w, reg_2 = w.pipeline.registration, two.pipeline.registration
    assert reg_w is not None and reg_2 is not None and reg_w.pairs > state.bias["pairs"]
    assert reg_2.pairs == reg_w.pairs
    assert reg_2.biases() == reg_w.biases()  # the same floats, σ included


@pytest.mark.parametrize(("field", "value", "match"), [
    ("b", [float("nan")] * 6, "'b'"), ("P", [[1.0, 2.0], [3.0, 4.0]], "'P'"),
    ("ids", [7], "'ids'"), ("meat", "x", "'meat'"), ("last", [[1, [[0, 1, None, None,
                                                                    None, None]]]], "last")])
def test_a_hostile_bias_state_is_refused(biased: Path, field: str, value: object,
                                         match: str) -> None:
    """A checkpoint's bias state is input: each bad field is named, nothing is set."""
    from mhtrack.pipeline.registration import Registration
    from mhtrack.pipeline.registration_state import encode_state, restore_state

    sensors = read_sensors(biased / "sensors.toml")
    good = json.loads(json.dumps(encode_state(Registration(sensors, reference=3))))
    reg = Registration(sensors, reference=3)
    before = encode_state(reg)
    with pytest.raises(ValueError, match=match):
        restore_state(reg, {**good, field: value})
    assert encode_state(reg) == before
    bad_p = json.loads(json.dumps(good))
    bad_p["P"][0][0] = -1.0
    with pytest.raises(ValueError, match="not a covariance"):
        restore_state(reg, bad_p)


def _scores(live: Live) -> list[float]:
    return live.pipeline.tracker.leaves.score.tolist()


YOUNG_MAP = TrackOptions(output="online", new_target_density=1e-10, tracker="mht-map",
                         startup_density=True, defer_tentative=True,
                         clutter_params={"half_life": 5.0, "n_azimuth": 8})


def test_the_tracking_options_go_through_the_checkpoint(rec: Path, tmp_path: Path) -> None:
    """Stopped and resumed with the same non-default options (young-track, clutter
    estimator's), the rows and the final tracks' scores are those of a run never stopped
    with them — whose scores are not those of the defaults; resumed with other options,
    refused naming each field; a checkpoint that kept no options (written before they
    were kept) is not checked."""
    blocks = _blocks(rec)
    k = len(blocks) // 2
    whole, w = _run(rec, blocks, track=YOUNG_MAP)
    _, p = _run(rec, blocks)
    assert _scores(w) != _scores(p)  # (the rows are the same on this recording)
    ck = tmp_path / "state.npz"
    first, _ = _run(rec, blocks[:k], stop_after=k, track=YOUNG_MAP, checkpoint=ck)
    tracker, state = read_checkpoint(ck, YOUNG_MAP)
    assert state.options is not None and state.options["clutter_params"] == {
        "half_life": 5.0, "n_azimuth": 8}
    second, two = _run(rec, blocks[k:], track=YOUNG_MAP, checkpoint=ck, resume=True)
    assert first + second == whole
    assert _scores(two) == _scores(w)
    other = replace(YOUNG_MAP, defer_tentative=None, clutter_params={"half_life": 5.0})
    with pytest.raises(InputError) as e:
        _run(rec, blocks[k:], track=other, checkpoint=ck, resume=True)
    assert str(e.value) == (
        f"{ck}: written with other tracking options (clutter_params {{'half_life': 5.0, "
        f"'n_azimuth': 8}} there, {{'half_life': 5.0}} here; defer_tentative True there, "
        "None here): resume with the same options, or start afresh without --resume")
    old = tmp_path / "old.npz"  # the same state without its options
    CheckpointSink(old, lambda: tracker, lambda: replace(state, options=None)).save()
    assert read_checkpoint(old, other)[1].options is None
    bad = tmp_path / "bad.npz"  # options that are no object: named, as other fields
    CheckpointSink(bad, lambda: tracker, lambda: replace(state, options=[1])).save()  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"field 'extra': options \[1\] are not an object"):
        read_checkpoint(bad, YOUNG_MAP)
