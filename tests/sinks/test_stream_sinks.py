"""The live sinks: CAT062 over UDP decoded by an independent decoder (pyasteryx) equals
the online rows within one LSB; rolling CAT062 parts hold the rows of the whole file;
JSON lines give the online rows."""

from __future__ import annotations

import io
import json
import math
import socket

import numpy as np
import pytest

pytest.importorskip("asterix")

from udp_drain import drain

from mhtrack.io import write_plots
from mhtrack.io.asterix.cat062 import lsb062, read_system_tracks
from mhtrack.io.sensors import write_sensors
from mhtrack.pipeline import Pipeline, TrackOptions
from mhtrack.scenario import preset, simulate
from mhtrack.scenario.overrides import apply_overrides
from mhtrack.sinks import Cat062Sink, TrackCollector
from mhtrack.sinks.stream import Cat062UdpSink, JsonLinesSink


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("stream")
    sc = apply_overrides(preset("opensky-radars"), scans=6)
    write_plots(simulate(sc, seed=1).plots, tmp / "plots.csv")
    write_sensors(sc.sensor_set(), tmp / "sensors.toml")
    pipe = Pipeline.open(str(tmp / "plots.csv"), TrackOptions(output="online"))
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    rx.bind(("127.0.0.1", 0))
    udp = Cat062UdpSink(f"udp://127.0.0.1:{rx.getsockname()[1]}", pipe.frame, sac=3, sic=4)
    rows, per_frame = TrackCollector("online"), []
    parts = Cat062Sink(tmp / "p.ast", pipe.frame, output="online", part_frames=25)
    whole = Cat062Sink(tmp / "w.ast", pipe.frame, output="online")
    text = io.StringIO()
    from mhtrack.sinks import CallbackSink

    result = pipe.run([udp, rows, parts, whole, JsonLinesSink(text, pipe.frame),
                       CallbackSink(lambda o: per_frame.append(len(o.online)))])
    got = drain(rx)
    rx.close()
    return {"pipe": pipe, "udp": udp, "rows": rows.tracks(), "got": got, "parts": parts,
            "whole": whole, "text": text.getvalue(), "frames": len(result.stats),
            "per_frame": per_frame}


def test_udp_cat062_decoded_by_pyasteryx_equals_the_online_rows(run: dict) -> None:
    pyasteryx = pytest.importorskip("pyasteryx")
    got, udp, t = run["got"], run["udp"], run["rows"]
    assert len(got) == udp.datagrams > 0, "loopback dropped CAT062 datagrams"
    recs = [m.items for d in got for m in pyasteryx.Decoder().decode(d)]
    assert len(recs) == len(t) == udp.rows
    # the encoder sends a frame's rows in time order (a row's time is its plot's):
    # both sides ordered by (time in LSBs of I062/070, track)
    tod = np.round(np.array([r["I062/070"]["ToT"] for r in recs]) / lsb062()["tod_s"])
    tn = np.array([r["I062/040"]["TrkN"] for r in recs])
    mine = np.lexsort((t.track_id, np.round(t.time / lsb062()["tod_s"])))
    theirs = np.lexsort((tn, tod))
    assert np.array_equal(tn[theirs], t.track_id[mine])
    recs = [recs[i] for i in theirs]
    lat, lon = run["pipe"].frame.to_geodetic(t.x, t.y)
    ve, vn = run["pipe"].frame.velocity_to_geodetic(t.x, t.y, t.vx, t.vy)
    L = lsb062()
    assert [r["I062/010"]["SAC"] * 256 + r["I062/010"]["SIC"] for r in recs] == \
        [3 * 256 + 4] * len(t)
    for key, sub, ref, tol in (("I062/105", "Lat", lat, L["deg"]),
                               ("I062/105", "Lon", lon, L["deg"]),
                               ("I062/185", "Vx", ve, L["mps"]),
                               ("I062/185", "Vy", vn, L["mps"]),
                               ("I062/070", "ToT", t.time, L["tod_s"])):
        assert np.abs(np.array([r[key][sub] for r in recs]) - ref[mine]).max() <= tol, sub
    assert [r["I062/080"]["CST"] for r in recs] == (t.plot[mine] < 0).astype(int).tolist()
    # frames with rows send ceil(rows / 40) datagrams, frames without none
    assert udp.datagrams == sum(math.ceil(n / 40) for n in run["per_frame"])


def test_rolling_parts_hold_the_whole_file(run: dict) -> None:
    parts, whole = run["parts"], run["whole"]
    assert len(parts.paths) == math.ceil(run["frames"] / 25) > 1
    cols = [read_system_tracks(p)[0] for p in parts.paths]
    ref, _ = read_system_tracks(whole.path)
    got = {k: np.concatenate([c[k] for c in cols]) for k in ref}
    # each file is in time order, and a frame's rows can be older than an earlier
    # frame's (radars interleave): the same rows, compared in (time, track) order
    a = np.lexsort((got["track_number"], got["time"]))
    b = np.lexsort((ref["track_number"], ref["time"]))
    for k in ("time", "track_number", "lat", "lon", "vx", "vy", "coasting"):
        assert np.array_equal(got[k][a], ref[k][b]), k


def test_json_lines_are_the_online_rows(run: dict) -> None:
    lines = [json.loads(x) for x in run["text"].splitlines()]
    t = run["rows"]
    assert len(lines) == len(t)
    assert [x["track_id"] for x in lines] == t.track_id.tolist()
    assert np.allclose([x["x"] for x in lines], t.x, atol=5e-4, rtol=0)
    assert np.allclose([x["vy"] for x in lines], t.vy, atol=5e-4, rtol=0)
    assert [x["coasting"] for x in lines] == (t.plot < 0).tolist()
    lat, _ = run["pipe"].frame.to_geodetic(t.x, t.y)
    assert np.allclose([x["lat"] for x in lines], lat, atol=1e-7, rtol=0)
