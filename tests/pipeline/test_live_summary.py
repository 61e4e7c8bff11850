"""The end-of-run summary line of ``live`` (:meth:`~mhtrack.pipeline.live.LiveResult.
describe`) names the plots and sector crossings dropped as too late for the re-order
window — the status line's ``late drops`` and ``late crossings`` — when there are any,
and nothing more when there are none: a run over a hand-built feed (CAT048 plots and
CAT034 marks, one datagram each, ``tests/helpers/sector_feed.py``) whose late ones are
worked out by hand."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from sector_feed import SENSORS, datagrams  # tests/helpers

from mhtrack.io.sensors import read_sensors
from mhtrack.pipeline import TrackOptions
from mhtrack.pipeline.live import Live, LiveOptions, LiveResult

# window 0: a plot or mark is late once a plot of a later time has gone on. Radar 1's
# crossing at 0.5 s comes after its plots at 0.625 and 0.75 s (1 late crossing); radar
# 2's plots at 0.25 and 0.5 s come after radar 1's at 1.0 s (2 late drops). Frames (as
# tests/sources/test_sector_close.py works out): radar 1 {0.125 … 0.75}, {0.875, 1.0},
# radar 2 {1.25}
FEED = [("n", 0.0, 1), ("p", 0.125, 1), ("p", 0.375, 1), ("p", 0.625, 1),
        ("p", 0.75, 1), ("s", 0.5, 1), ("p", 0.875, 1), ("p", 1.0, 1),
        ("p", 0.25, 2), ("p", 0.5, 2), ("p", 1.25, 2)]
LATE = {5, 8, 9}  # the late datagrams' places in FEED


def _run(feed: list[tuple[str, float, int]], tmp: Path) -> tuple[Live, LiveResult]:
    """``live --stdin raw --sector-frames --reorder-window 0`` over the feed's file."""
    (tmp / "sensors.toml").write_text(SENSORS)
    (tmp / "feed.ast").write_bytes(b"".join(datagrams(feed)))
    with (tmp / "feed.ast").open("rb") as f:
        live = Live(read_sensors(tmp / "sensors.toml"),
                    TrackOptions(output="online", new_target_density=1e-10),
                    LiveOptions(preload=False, stdin="raw", day_from="stream",
                                sectors=True, reorder_window_s=0.0),
                    stdin=f, stdout=io.StringIO())
        return live, live.run()


def _fixed(line: str) -> str:
    """The line without what the machine decides: the tracker's ms per frame and the
    latency (the frames timed depend on how the reader thread's reads fall)."""
    line = re.sub(r"\d+\.\d\d ms/scan", "T ms/scan", line)
    return re.sub(r"; latency p50 -?\d+ ms, p99 -?\d+ ms \(\d+ frames\)$", "", line)


def test_the_summary_names_late_plots_and_crossings(tmp_path: Path) -> None:
    live, result = _run(FEED, tmp_path)
    st = live.source.stats  # the counts the status line and JSON show: the same ones
    assert (st.late_dropped, st.late_crossings) == (2, 1)
    assert (result.health["late_drops"], result.health["late_crossings"]) == (2, 1)
    assert _fixed(result.describe()) == (
        "received 11 datagrams (0 dropped in the queue), 2 late drops, 1 late crossings; "
        "mht-agmm: 3 frames, 0 tracks, T ms/scan; sent 0 CAT062 datagrams (0 rows)")


def test_nothing_late_nothing_more_in_the_summary(tmp_path: Path) -> None:
    # the late datagrams left out: radar 1's frame is cut by the eighth of its turn
    # alone (1.0 − 0.125 ≤ 1 s): {0.125 … 1.0}, then radar 2's {1.25}
    feed = [x for i, x in enumerate(FEED) if i not in LATE]
    _, result = _run(feed, tmp_path)
    assert (result.health["late_drops"], result.health["late_crossings"]) == (0, 0)
    assert _fixed(result.describe()) == (
        "received 8 datagrams (0 dropped in the queue); "
        "mht-agmm: 2 frames, 0 tracks, T ms/scan; sent 0 CAT062 datagrams (0 rows)")
