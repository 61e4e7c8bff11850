"""Frames closed at the radar's own sector crossings (``sectors=True``,
:mod:`mhtrack.sources.framer`, :mod:`mhtrack.sources.marks`): a hand-built recording —
CAT048 plots and CAT034 north markers / sector crossings, one datagram per message — whose
frames and the datagram after which each frame leaves are worked out by hand; a radar
without CAT034 keeps the eighth-of-a-turn rule; lost crossings do not hold a frame past
that rule."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from sector_feed import SENSORS, T0, datagrams  # tests/helpers

from mhtrack.io.sensors import read_sensors
from mhtrack.sources.datagrams import DatagramSource


def _frames(feed: list[tuple[str, float, int]], tmp: Path, sectors: bool,
            release: str = "time") -> list[tuple[int, list[float], int]]:
    """``(sensor, plot times − T0, datagrams read when it left)`` of each frame of the
    feed (``("p"|"n"|"s", time, sensor)``: plot, north marker, sector crossing)."""
    (tmp / "sensors.toml").write_text(SENSORS)
    grams = datagrams(feed)
    read = [0]

    def counted():
        for g in grams:
            read[0] += 1
            yield g

    src = DatagramSource(counted(), sensors=read_sensors(tmp / "sensors.toml"),
                         reorder_window_s=0.0, sectors=sectors, chunk=1,
                         release=release)
    return [(int(f.sensor[0]), [round(x - T0, 3) for x in f.t.tolist()], read[0])
            for f in src]


# radar 1 sends a north marker and a crossing every 0.5 s (1/16 turn; its frame length is
# 8 s / 8 = 1 s); radar 2 sends no CAT034 at all
FEED = [("n", 0.0, 1), ("p", 0.125, 1), ("p", 0.25, 2), ("p", 0.375, 1),
        ("s", 0.5, 1),                                    # 5th: radar 1's sector 1 done
        ("p", 0.625, 2),                                  # 6th: releases the crossing
        ("p", 0.75, 1), ("p", 0.875, 1), ("s", 1.0, 1), ("p", 1.125, 2),   # 7th–10th
        ("p", 1.25, 1), ("p", 1.5, 2)]                    # 11th, 12th


def test_hand_built_recording_frames_close_at_the_crossing(tmp_path: Path) -> None:
    # radar 1: one frame per sector, closed by the crossing after it once the crossing
    # has passed the re-order window (window 0: the next datagram with a later time);
    # radar 2 (no CAT034): eighths, [0.25, 1.25] s from its first plot
    frames = [[0.125, 0.375], [0.75, 0.875], [0.25, 0.625, 1.125], [1.25], [1.5]]
    by_radar = _frames(FEED, tmp_path, sectors=True, release="radar")
    assert by_radar == [(1, frames[0], 6),   # the crossing at 0.5 s, released by 0.625
                        (1, frames[1], 10),  # the crossing at 1.0 s, released by 1.125
                        (2, frames[2], 12),  # the end of the input (1.5 − 0.25 > 1)
                        (1, frames[3], 12), (2, frames[4], 12)]
    # in track's order a closed frame also waits for radar 2's open frame while that
    # frame's end (0.25, then 0.625) is before its own: one datagram later here
    assert _frames(FEED, tmp_path, sectors=True) == [
        (1, frames[0], 7), (1, frames[1], 11), *by_radar[2:]]
    # without the option: eighths for both; radar 1's first frame is closed by its plot
    # at 1.25 > 0.125 + 1, released by the 12th datagram
    assert _frames(FEED, tmp_path, sectors=False) == [
        (1, [0.125, 0.375, 0.75, 0.875], 12), (2, frames[2], 12),
        (1, [1.25], 12), (2, [1.5], 12)]


def test_lost_crossings_fall_back_to_the_eighth(tmp_path: Path) -> None:
    # radar 1's crossings after 0.5 s are lost: its frame of sector 2 keeps its plots up
    # to its first plot + 1 s (the eighth-of-a-turn rule), then the next starts
    feed = [("n", 0.0, 1), ("p", 0.125, 1), ("s", 0.5, 1), ("p", 0.625, 1),
            ("p", 0.875, 1), ("p", 1.25, 1), ("p", 1.625, 1), ("p", 1.75, 1),
            ("p", 2.0, 2), ("p", 2.875, 2)]
    got = _frames(feed, tmp_path, sectors=True)
    assert got == [(1, [0.125], 4),  # the crossing at 0.5 s, released by 0.625
                   # 1.75 > 0.625 + 1 closes it, released by the 9th datagram (2.0)
                   (1, [0.625, 0.875, 1.25, 1.625], 9),
                   (1, [1.75], 10), (2, [2.0, 2.875], 10)]  # the end of the input


def _timed(feed: list[tuple[str, float, int]], tmp: Path) -> tuple[list, object]:
    """The feed through ``DatagramSource`` into a live run's health bookkeeping
    (:class:`~mhtrack.pipeline.health.Health`), datagram ``i`` received at stamp
    ``1000 + i`` and every frame out at stamp 10 000 (as ``live``'s reader does:
    :meth:`Arrivals.add` as each datagram is taken): the frames and the health."""
    from types import SimpleNamespace

    from mhtrack.pipeline.health import Health

    (tmp / "sensors.toml").write_text(SENSORS)
    grams = datagrams(feed)
    health = Health(lambda: {}, lambda: 0, lambda o: src.file_rows(o.frame.rows),
                    {1: 8.0, 2: 8.0}, lambda: 10_000.0)

    def noted():
        for i, g in enumerate(grams):
            health.arrivals.add(src.decoded, 1000.0 + i, len(g))
            yield g
        health.input_ended = True

    src = DatagramSource(noted(), sensors=read_sensors(tmp / "sensors.toml"),
                         reorder_window_s=0.0, sectors=True, chunk=1, release="radar")
    frames = []
    for f in src:
        frames.append(f)
        health.write(SimpleNamespace(frame=f))  # type: ignore[arg-type]
    starts = np.cumsum([0, *map(len, grams)])  # each datagram's first byte
    return [(int(f.sensor[0]), None if f.closing is None else
             int(np.searchsorted(starts, f.closing, side="right")) - 1) for f in frames], \
        health


def test_latency_of_a_sector_is_timed_from_its_closing_crossing(tmp_path: Path) -> None:
    # FEED's frames (above): radar 1's [0.125, 0.375] closed by the crossing at 0.5 s
    # (datagram 4; its last plot in datagram 3), [0.75, 0.875] by the crossing at 1.0 s
    # (datagram 8; last plot in 7); the last three by the end of the input (not timed)
    closing, health = _timed(FEED, tmp_path)
    assert closing == [(1, 4), (1, 8), (2, None), (1, None), (2, None)]
    k = health.latency_count
    assert k == 2 and health.after_end == 3 and health.by_crossing == 2
    assert (10_000.0 - health.recent[:k]).tolist() == [1004.0, 1008.0]
    assert (10_000.0 - health.recent_last_plot[:k]).tolist() == [1003.0, 1007.0]
    lat = health.snapshot()["latency_s"]
    assert (lat["p50"], lat["last_plot"]["p50"]) == (8994.0, 8995.0)


def test_a_fallback_frame_keeps_its_last_plot_s_datagram(tmp_path: Path) -> None:
    # the lost crossings' feed: the first frame is closed by the crossing at 0.5 s
    # (datagram 2, its plot in 1); the next by radar 1's plot at 1.75 s past the eighth
    # (its last plot at 1.625 s in datagram 6), whatever came before
    feed = [("n", 0.0, 1), ("p", 0.125, 1), ("s", 0.5, 1), ("p", 0.625, 1),
            ("p", 0.875, 1), ("p", 1.25, 1), ("p", 1.625, 1), ("p", 1.75, 1),
            ("p", 2.0, 2), ("p", 2.875, 2)]
    closing, health = _timed(feed, tmp_path)
    assert closing[:2] == [(1, 2), (1, None)]
    k = health.latency_count
    assert k == 2 and health.by_crossing == 1
    assert (10_000.0 - health.recent[:k]).tolist() == [1002.0, 1006.0]
    assert (10_000.0 - health.recent_last_plot[:k]).tolist() == [1001.0, 1006.0]


def test_a_late_crossing_is_counted_as_one_not_as_a_late_plot(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # radar 1's crossing at 0.5 s comes after its plots at 0.625 and 0.75 s (datagram 6):
    # with window 0 the plot at 0.75 s had released 0.625 s, so the crossing (0.5 s) can
    # no longer be put in order: dropped, counted as a late crossing, not a late plot.
    # The plots decoded before it still count sector 1 (they join the open frame, which
    # stays within its eighth: 0.75 − 0.125 ≤ 1 s); those decoded after it count sector
    # 2, so radar 1's next plot (0.875 s) closes the frame, released by 1.0 s (8th)
    feed = [("n", 0.0, 1), ("p", 0.125, 1), ("p", 0.375, 1), ("p", 0.625, 1),
            ("p", 0.75, 1), ("s", 0.5, 1), ("p", 0.875, 1), ("p", 1.0, 1),
            ("p", 1.25, 2)]
    (tmp_path / "sensors.toml").write_text(SENSORS)
    grams = datagrams(feed)
    src = DatagramSource(grams, sensors=read_sensors(tmp_path / "sensors.toml"),
                         reorder_window_s=0.0, sectors=True, chunk=1)
    frames = [(int(f.sensor[0]), [round(x - T0, 3) for x in f.t.tolist()], f.closing)
              for f in src]
    assert frames == [(1, [0.125, 0.375, 0.625, 0.75], None), (1, [0.875, 1.0], None),
                      (2, [1.25], None)]
    st = src.stats
    assert (st.late_dropped, st.late_crossings) == (0, 1)
    assert st.plots_in == st.plots_out == 7  # every plot tracked, none dropped
    # one warning line of its own: late by M − t = 0.75 − 0.5 s, at its datagram's byte
    at = sum(map(len, grams[:5]))
    assert [r.getMessage() for r in caplog.records if "dropped" in r.getMessage()] == [
        f"datagrams: 1 sector crossing dropped, late by 0.25 s (after later plots had gone "
        f"to the tracker, beyond the reorder window; first at byte {at})"]
    # the same stream with the crossing lost instead: no plot counts sector 2, so the
    # eighth alone cuts radar 1's frame (1.0 − 0.125 ≤ 1 s: one frame to the end)
    lost = [g for i, g in enumerate(grams) if i != 5]
    src2 = DatagramSource(lost, sensors=read_sensors(tmp_path / "sensors.toml"),
                          reorder_window_s=0.0, sectors=True, chunk=1)
    assert [[round(x - T0, 3) for x in f.t.tolist()] for f in src2] == \
        [[0.125, 0.375, 0.625, 0.75, 0.875, 1.0], [1.25]]
    assert (src2.stats.late_dropped, src2.stats.late_crossings) == (0, 0)
