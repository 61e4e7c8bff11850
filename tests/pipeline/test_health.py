"""Health and latency of a live run (:mod:`mhtrack.pipeline.health`,
:mod:`mhtrack.pipeline.monitor`): each plot's datagram found against a brute-force
search, the latency percentiles against numpy on known latencies, the Prometheus text
parsed back by prometheus_client's parser (and by the format's rules), the JSON status
file and the HTTP endpoint."""

from __future__ import annotations

import json
import math
import re
import urllib.request
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.pipeline.health import Arrivals, Health
from mhtrack.pipeline.monitor import (
    CONTENT_TYPE,
    MetricsServer,
    prometheus_text,
    write_status,
)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 5), min_size=1, max_size=60), st.integers(1, 20))
def test_arrivals_against_brute_force(plots_per_datagram: list[int], keep: int) -> None:
    """Datagram ``i`` (received at time ``i``) holds the next ``plots_per_datagram[i]``
    plots: each plot's receive time is its datagram's, or ``None`` when the datagram is
    older than the last ``keep``."""
    arr = Arrivals(keep)
    owner: list[int] = []
    for i, n in enumerate(plots_per_datagram):
        arr.add(len(owner), float(i))
        owner += [i] * n
    last = len(plots_per_datagram) - 1
    for plot, i in enumerate(owner):
        want = float(i) if i > last - keep else None
        assert arr.time_of(plot) == want, (plot, i)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 7), min_size=1, max_size=60), st.integers(1, 20))
def test_arrivals_by_byte_against_brute_force(sizes: list[int], keep: int) -> None:
    """Datagram ``i`` (received at time ``i``) holds the next ``sizes[i]`` bytes (some
    none): :meth:`Arrivals.time_at` of every byte is its datagram's time while that is
    among the last ``keep``, else ``None``; a byte not yet received has none."""
    arr = Arrivals(keep)
    owner: list[int] = []
    for i, n in enumerate(sizes):
        arr.add(0, float(i), n)
        owner += [i] * n
    last = len(sizes) - 1
    for byte, i in enumerate(owner):
        assert arr.time_at(byte) == (float(i) if i > last - keep else None), (byte, i)
    assert arr.time_at(len(owner)) is None and arr.time_at(-1) is None


def _health(clock_values: list[float], arrivals: Arrivals | None = None) -> Health:
    clock = iter(clock_values)
    return Health(lambda: {"datagrams": 5, "queue_drops": 0, "plots": 9, "duplicates": 1,
                           "late_drops": 2}, lambda: 4,
                  lambda out: np.asarray(out.frame.rows), {1: 4.0},
                  lambda: next(clock), arrivals=arrivals)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_percentiles_against_numpy(seed: int) -> None:
    """Frames with known latencies, through the datagram look-up: the snapshot's p50 and
    p99 are numpy's percentiles of those latencies; the line's those since the last
    line."""
    rng = np.random.default_rng(seed)
    n = 500
    t_in = np.cumsum(rng.exponential(0.1, n))  # datagram i holds plot i
    latency = rng.lognormal(-3, 1, n)
    arr = Arrivals()
    for i in range(n):
        arr.add(i, float(t_in[i]))
    # frame j has plots j-2 .. j: its last datagram is j's
    h = _health([*(t_in + latency).tolist(), 1e9, 1e9], arr)
    for j in range(n):
        h.write(SimpleNamespace(frame=SimpleNamespace(
            time=float(j), sensor=np.array([1]), rows=np.arange(max(0, j - 2), j + 1))))
    snap = h.snapshot()
    want = np.percentile(latency, [50, 99])
    assert snap["latency_s"]["p50"] == pytest.approx(want[0], rel=1e-12)
    assert snap["latency_s"]["p99"] == pytest.approx(want[1], rel=1e-12)
    assert snap["latency_s"]["count"] == n
    assert snap["latency_s"]["sum"] == pytest.approx(latency.sum(), rel=1e-12)
    m = re.search(r"latency p50 (\d+) ms p99 (\d+) ms", h.line(snap))
    assert m and [int(x) for x in m.groups()] == [round(1e3 * v) for v in want]


def _snapshot() -> dict:
    h = _health([10.5, 11.0, 12.0, 13.0])  # two frames out, then snapshots
    h.arrivals.add(0, 9.9)
    for t in (1.0, 2.0):
        h.write(SimpleNamespace(frame=SimpleNamespace(time=t, sensor=np.array([1]),
                                                      rows=np.array([0]))))
    return h.snapshot()


def test_prometheus_text_parsed_back() -> None:
    parser = pytest.importorskip("prometheus_client.parser",
                                 reason="prometheus_client (extra [reference])")
    snap = _snapshot()  # latencies 0.6 s and 1.1 s
    text = prometheus_text(snap)
    fams = {f.name: f for f in parser.text_string_to_metric_families(text)}
    # prometheus_client names a counter family without its _total suffix
    assert fams["mhtrack_live_datagrams"].type == "counter"
    assert fams["mhtrack_live_datagrams"].samples[0].value == 5
    assert fams["mhtrack_live_late_drops"].samples[0].value == 2
    assert fams["mhtrack_live_duplicates"].samples[0].value == 1
    assert fams["mhtrack_live_tracks"].type == "gauge"
    assert fams["mhtrack_live_tracks"].samples[0].value == 4
    assert fams["mhtrack_live_frames"].samples[0].value == 2
    lat = fams["mhtrack_live_latency_seconds"]
    assert lat.type == "summary"
    got = {(s.name, s.labels.get("quantile")): s.value for s in lat.samples}
    assert got[("mhtrack_live_latency_seconds", "0.5")] == pytest.approx(0.85)
    assert got[("mhtrack_live_latency_seconds", "0.99")] == pytest.approx(0.6 + 0.99 * 0.5)
    assert got[("mhtrack_live_latency_seconds_sum", None)] == pytest.approx(1.7)
    assert got[("mhtrack_live_latency_seconds_count", None)] == 2


def test_prometheus_text_by_the_format_rules() -> None:
    """Text format 0.0.4: ``# HELP``/``# TYPE`` before each family's samples, sample
    lines ``name{labels} value``, names of ``[a-zA-Z_:][a-zA-Z0-9_:]*``, a final
    newline; NaN for no latency yet."""
    text = prometheus_text({**_snapshot(), "latency_s": {"p50": math.nan, "p99": math.nan,
                                                        "sum": 0.0, "count": 0}})
    assert text.endswith("\n")
    name = r"[a-zA-Z_:][a-zA-Z0-9_:]*"
    typed: dict[str, str] = {}
    for line in text.splitlines():
        if line.startswith("# HELP "):
            assert re.fullmatch(rf"# HELP {name} .+", line)
        elif line.startswith("# TYPE "):
            m = re.fullmatch(rf"# TYPE ({name}) (counter|gauge|summary)", line)
            assert m
            typed[m.group(1)] = m.group(2)
        else:
            m = re.fullmatch(rf"({name})(\{{quantile=\"[0-9.]+\"\}})? (\S+)", line)
            assert m, line
            base = re.sub(r"_(sum|count)$", "", m.group(1))
            assert m.group(1) in typed or typed.get(base) == "summary", line
            float(m.group(3))  # NaN included
            if typed.get(m.group(1)) == "counter":
                assert m.group(1).endswith("_total")
    assert 'mhtrack_live_latency_seconds{quantile="0.5"} NaN' in text


def test_json_status_file_and_http(tmp_path: Path) -> None:
    snap = _snapshot()
    write_status(snap, tmp_path / "status.json", tmp_path / "metrics.prom")
    got = json.loads((tmp_path / "status.json").read_text())
    assert got["datagrams"] == 5 and got["frames"] == 2 and got["tracks"] == 4
    assert got["latency_s"]["count"] == 2 and got["radars_silent"] == []
    assert (tmp_path / "metrics.prom").read_text() == prometheus_text(snap)
    server = MetricsServer("127.0.0.1", 0)
    try:
        server.update(prometheus_text(snap))
        host, port = server.address
        with urllib.request.urlopen(f"http://{host}:{port}/metrics", timeout=10) as r:
            assert r.headers["Content-Type"] == CONTENT_TYPE
            assert r.read().decode() == prometheus_text(snap)
        with pytest.raises(urllib.error.HTTPError, match="404"):
            urllib.request.urlopen(f"http://{host}:{port}/other", timeout=10)
    finally:
        server.close()


def test_frames_made_by_the_end_are_not_timed() -> None:
    h = _health([10.5, 30.0, 31.0])
    h.arrivals.add(0, 9.9)
    frame = SimpleNamespace(frame=SimpleNamespace(time=1.0, sensor=np.array([1]),
                                                  rows=np.array([0])))
    h.write(frame)
    h.input_ended = True  # the stop flushes a frame 20 s later: not a latency of the data
    h.write(frame)
    lat = h.snapshot()["latency_s"]
    assert (lat["count"], lat["after_end"], h.frames) == (1, 1, 2)
    assert lat["p99"] == pytest.approx(0.6)


def test_late_crossings_have_their_own_figure() -> None:
    """Sector crossings too late for the re-order window are counted apart from late
    plots: their own word in the line (when there are any) and their own counter in the
    Prometheus text, beside ``late_drops``."""
    counts = {"datagrams": 5, "queue_drops": 0, "plots": 9, "duplicates": 1,
              "late_drops": 2, "late_crossings": 3}
    h = Health(lambda: counts, lambda: 4, lambda out: np.asarray(out.frame.rows), {},
               lambda: 1.0)
    snap = h.snapshot()
    assert (snap["late_drops"], snap["late_crossings"]) == (2, 3)
    assert "2 late drops, 3 late crossings, 0 queue drops" in h.line(snap)
    text = prometheus_text(snap).splitlines()
    assert "mhtrack_live_late_crossings_total 3" in text
    assert "mhtrack_live_late_drops_total 2" in text
    counts["late_crossings"] = 0  # none: the line as without sector frames
    assert "2 late drops, 0 queue drops" in h.line(h.snapshot())
