"""A live run with sector frames (``--sector-frames``) stopped with a checkpoint and
resumed (:mod:`mhtrack.pipeline.checkpoint`: the plots held, with the sector crossings
among them and each radar's count of crossings): on a hand-built feed — CAT048 plots and
CAT034 crossings, one datagram each, worked out by hand — the resumed run makes the
frames of the run never stopped, and its latency bookkeeping
(:class:`~mhtrack.pipeline.health.Health`) times a frame of held plots from the
crossing that closed it after the restart, and leaves out (``restored``) one closed by a
crossing held in the checkpoint too — whether the datagrams come queued up or each on
its own (``live`` passes on what it has decoded whenever its queue is empty:
:data:`~mhtrack.sources.base.CAUGHT_UP`; a crossing is then a chunk of its own, with no
plot of the resumed run yet to give its row the columns of a plot)."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from sector_feed import SENSORS, T0, datagrams  # tests/helpers

from mhtrack.errors import InputError
from mhtrack.io.sensors import read_sensors
from mhtrack.pipeline import TrackOptions
from mhtrack.pipeline.checkpoint import (
    LiveState,
    check_options,
    decode_pending,
    encode_pending,
    options_record,
)
from mhtrack.pipeline.health import Health
from mhtrack.sources.base import CAUGHT_UP
from mhtrack.sources.datagrams import DatagramSource

# radar 1: a north marker at 0 s, a crossing into its next sector every 0.5 s (1/16 of
# its 8 s turn; frames of at most 1 s); radar 2: one plot, at the end
FEED = [("n", 0.0, 1), ("p", 0.125, 1), ("p", 0.25, 1), ("s", 0.5, 1), ("p", 0.625, 1),
        ("p", 0.75, 1), ("s", 1.0, 1), ("p", 1.125, 1), ("p", 1.25, 2)]
#: The frames of the run never stopped (window 0): (radar, plot times, the datagram of
#: the crossing that closed it): radar 1's {0.125, 0.25} closed by the crossing at 0.5 s
#: (datagram 3), {0.625, 0.75} by the one at 1.0 s (datagram 6); the end makes the rest.
FRAMES = [(1, [0.125, 0.25], 3), (1, [0.625, 0.75], 6), (1, [1.125], None),
          (2, [1.25], None)]


def _frames(scans, grams: list[bytes], first: int = 0) -> list[tuple]:
    """``(radar, plot times − T0, the index in FEED of the closing crossing's datagram or
    None)`` of each frame; ``grams`` the datagrams the source read, FEED's from
    ``first`` on."""
    starts = np.cumsum([0, *map(len, grams)])  # each datagram's first byte
    return [(int(f.sensor[0]), [round(x - T0, 3) for x in f.t.tolist()],
             None if f.closing is None
             else first + int(np.searchsorted(starts, f.closing, side="right")) - 1)
            for f in scans]


def _resumed(stop: int, tmp: Path, alone: bool = False) -> tuple[list, Health]:
    """FEED's first ``stop`` datagrams, held at the end (a stop with a checkpoint; what
    is held goes through the checkpoint's JSON), then a run resumed on the rest: the
    frames of both (:func:`_frames`) and the second run's health — datagram ``i`` after
    the restart received at stamp ``2000 + i``, every frame out at stamp 10 000; with
    ``alone``, each datagram of both runs followed by ``CAUGHT_UP`` (decoded and passed
    on alone, as ``live`` does when no other is waiting)."""
    (tmp / "sensors.toml").write_text(SENSORS)
    sensors = read_sensors(tmp / "sensors.toml")
    grams = datagrams(FEED)
    one = DatagramSource(_alone(grams[:stop]) if alone else grams[:stop],
                         sensors=sensors, reorder_window_s=0.0, sectors=True, chunk=1,
                         hold=lambda: True)
    before = list(one)
    saved = json.loads(json.dumps(encode_pending(one.pending())))  # as a checkpoint
    health = Health(lambda: {}, lambda: 0, lambda o: two.file_rows(o.frame.rows),
                    {1: 8.0, 2: 8.0}, lambda: 10_000.0)

    def noted() -> Iterator[bytes]:
        for i, g in enumerate(grams[stop:]):
            health.arrivals.add(two.decoded, 2000.0 + i, len(g))
            yield g
            if alone:
                yield CAUGHT_UP
        health.input_ended = True

    two = DatagramSource(noted(), sensors=sensors, reorder_window_s=0.0, sectors=True,
                         chunk=1, pending=decode_pending(saved), axis=one.axis,
                         first_frame=one.next_frame, first_row=one.next_row,
                         not_before=before[-1].time if before else None)
    after = []
    for f in two:
        after.append(f)
        health.write(SimpleNamespace(frame=f))  # type: ignore[arg-type]
    return _frames(before, grams[:stop]) + _frames(after, grams[stop:], stop), health


def _alone(grams: list[bytes]) -> Iterator[bytes]:
    """Each datagram followed by ``CAUGHT_UP``."""
    for g in grams:
        yield g
        yield CAUGHT_UP  # type: ignore[misc]


@pytest.mark.parametrize("alone", [False, True])
def test_the_frames_of_the_run_never_stopped(tmp_path: Path, alone: bool) -> None:
    (tmp_path / "sensors.toml").write_text(SENSORS)
    grams = datagrams(FEED)
    whole = DatagramSource(_alone(grams) if alone else grams,
                           sensors=read_sensors(tmp_path / "sensors.toml"),
                           reorder_window_s=0.0, sectors=True, chunk=1)
    assert _frames(whole, grams) == FRAMES  # the hand-worked frames
    for stop in range(1, len(FEED)):
        # stop 3: the crossing at 0.5 s is the resumed run's first datagram; alone, it
        # comes before any plot of that run, and still closes the frame held
        got, _ = _resumed(stop, tmp_path, alone)
        # a crossing held in the checkpoint (stop 4, 7: in the re-order window) closes
        # its frame again, but is no datagram of the resumed run's input: no offset
        held = {4: 3, 7: 6}.get(stop)
        assert got == [(r, t, None if c == held else c) for r, t, c in FRAMES], stop


@pytest.mark.parametrize("alone", [False, True])
def test_held_plots_are_timed_from_the_crossing_received_since(tmp_path: Path,
                                                               alone: bool) -> None:
    # stopped after 3 datagrams: radar 1's plots at 0.125 s (framed) and 0.25 s (in the
    # window) held; the crossing at 0.5 s comes after the restart (its datagram 0,
    # stamp 2000) and closes their frame: the sector's last datagram, later than every
    # plot held. The next frame as in a run never stopped: its crossing in datagram 3
    # (2003), its last plot in 2 (2002). The end's two frames are not timed
    _, health = _resumed(3, tmp_path, alone)
    k = health.latency_count
    assert (k, health.by_crossing, health.restored, health.untimed) == (2, 2, 0, 0)
    assert (10_000.0 - health.recent[:k]).tolist() == [2000.0, 2003.0]
    assert (10_000.0 - health.recent_last_plot[:k]).tolist() == [2000.0, 2002.0]
    assert health.after_end == 2


@pytest.mark.parametrize("alone", [False, True])
def test_a_frame_closed_before_the_restart_is_left_out(tmp_path: Path, alone: bool) -> None:
    # stopped after 4 datagrams: the crossing at 0.5 s is held too (window 0: the
    # re-order window keeps the latest row); after the restart the plot at 0.625 s
    # releases it and it closes {0.125, 0.25}: every datagram of that frame came before
    # the restart — timed by the restart, not by the data: counted apart, not timed
    _, health = _resumed(4, tmp_path, alone)
    k = health.latency_count
    assert (k, health.by_crossing, health.restored, health.untimed) == (1, 1, 1, 0)
    assert (10_000.0 - health.recent[:k]).tolist() == [2002.0]  # crossing at 1.0 s
    assert health.snapshot()["latency_s"]["restored"] == 1


@pytest.mark.parametrize("bad", [{"1": -1}, {"x": 2}, {"1": 1.5}, {"1": True}, [1]])
def test_a_count_of_crossings_that_is_none_is_refused(bad: object) -> None:
    saved = {"latest": None, "released": None, "framed": None, "held": None, "marks": bad}
    with pytest.raises(ValueError, match="marks"):
        decode_pending(saved)
    assert decode_pending({**saved, "marks": {"3": 7}})["marks"] == {3: 7}


def _saved(stop: int, tmp: Path, sectors: bool = True) -> dict:
    """The checkpoint's JSON of what FEED's first ``stop`` datagrams leave held."""
    (tmp / "sensors.toml").write_text(SENSORS)
    one = DatagramSource(datagrams(FEED)[:stop], sensors=read_sensors(tmp / "sensors.toml"),
                         reorder_window_s=0.0, sectors=sectors, chunk=1, hold=lambda: True)
    list(one)
    return json.loads(json.dumps(encode_pending(one.pending())))


def test_held_sectors_without_their_counts_are_refused(tmp_path: Path) -> None:
    # stopped after 5 datagrams: {0.125, 0.25} went out (closed by the crossing at
    # 0.5 s); the plot at 0.625 s is held (window 0) in radar 1's sector 2 — 2 marks so
    # far. Without the count (the previous mhtrack wrote none) the resumed run would
    # number the crossing at 1.0 s sector 1: it would not close {0.625, 0.75}
    saved = _saved(5, tmp_path)
    assert saved["held"]["sector"]["values"] == [2] and saved["marks"] == {"1": 2}
    old = {k: v for k, v in saved.items() if k != "marks"}
    with pytest.raises(ValueError, match=r"^pending: plots held with their sectors but no "
                       r"'marks' .*: written before sector counts were kept: start "
                       r"afresh without --resume$"):
        decode_pending(old)
    plain = _saved(5, tmp_path, sectors=False)  # no sectors held: no count needed
    assert "sector" not in plain["held"]
    assert decode_pending({k: v for k, v in plain.items() if k != "marks"})["marks"] == {}


@pytest.mark.parametrize("sectors", [False, True])
def test_rows_held_go_on_only_as_they_were_cut(tmp_path: Path, sectors: bool) -> None:
    # held with sectors, resumed without: the crossing held became a plot of NaN; the
    # other way round the framer failed on the missing sector column (KeyError)
    (tmp_path / "sensors.toml").write_text(SENSORS)
    saved = _saved(4, tmp_path, sectors)
    was, now = ("with", "without") if sectors else ("without", "with")
    with pytest.raises(ValueError, match=f"^pending: rows held cut {was} their sectors, "
                       f"this stream's {now}$"):
        DatagramSource(datagrams(FEED)[4:], sensors=read_sensors(tmp_path / "sensors.toml"),
                       sectors=not sectors, pending=decode_pending(saved))


def _state(pending: dict | None, options: dict | None) -> LiveState:
    return LiveState(next_frame=1, axis_day0=None, axis_latest=None, last_time=None,
                     next_tick=None, pending=pending, options=options)


@pytest.mark.parametrize("sectors", [False, True])
def test_a_resume_with_sector_frames_toggled_is_refused(tmp_path: Path,
                                                        sectors: bool) -> None:
    saved = _saved(4, tmp_path, sectors)
    opts = TrackOptions()
    line = (f"ck.npz: written with other tracking options (sector_frames {sectors} there, "
            f"{not sectors} here): resume with the same options, or start afresh without "
            "--resume")
    record = options_record(opts, sectors)
    assert record["sector_frames"] is sectors
    older = {k: v for k, v in record.items() if k != "sector_frames"}
    # kept with the options; else (written before) told by the held plots' columns
    for state in (_state(saved, record), _state(None, record), _state(saved, older),
                  _state(saved, None)):
        check_options("ck.npz", state, opts, sectors)  # the same: fine
        with pytest.raises(InputError) as e:
            check_options("ck.npz", state, opts, not sectors)
        assert str(e.value) == line
    for state in (_state(None, older), _state(None, None)):  # nothing tells: not checked
        check_options("ck.npz", state, opts, not sectors)
