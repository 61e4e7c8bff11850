"""Our tracks scored against a reference system's CAT062 tracks (issue 28, deliverable 2):
the sampling rule worked by hand, and the property that tracks exported as CAT062 and
taken as the reference score as themselves, within the items' LSBs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mhtrack.metrics.reference import (
    evaluate_reference,
    reference_truth,
    runs,
    tracks_at_reference,
    update_period,
)
from mhtrack.records import TrackTable


def _state(x: list[float]) -> np.ndarray:
    return np.column_stack((x, np.zeros(len(x)), np.zeros(len(x)), np.zeros(len(x))))


def test_interpolated_at_the_common_times_by_hand() -> None:
    """Updates at 0 s (x 0) and 4 s (x 100) sampled every 1 s: 0, 25, 50, 75, 100 m; a
    second track from 1 s to 2 s (x 10 → 30) at 1 s and 2 s only (never extrapolated)."""
    time = np.array([0.0, 4.0, 1.0, 2.0])
    key = np.array([7, 7, 9, 9])
    truth, period = reference_truth(time, key, _state([0.0, 100.0, 10.0, 30.0]),
                                    max_gap_s=15.0, period_s=1.0)
    assert period == 1.0
    a = truth.target_id == 0
    assert truth.scan[a].tolist() == [0, 1, 2, 3, 4]
    assert truth.x[a].tolist() == [0.0, 25.0, 50.0, 75.0, 100.0]
    b = truth.target_id == 1
    assert truth.scan[b].tolist() == [1, 2] and truth.x[b].tolist() == [10.0, 30.0]
    assert truth.time.tolist() == truth.scan.astype(float).tolist()


def test_a_gap_longer_than_max_gap_starts_a_new_target() -> None:
    """Track number 5 at 0, 2, 4 s and again at 40, 42 s (reused): two targets; the
    period is the median interval between consecutive updates of one target, 2 s."""
    time = np.array([0.0, 2.0, 4.0, 40.0, 42.0])
    key = np.full(5, 5)
    assert runs(key, time, 15.0).tolist() == [0, 0, 0, 1, 1]
    assert update_period(runs(key, time, 15.0), time) == 2.0
    truth, period = reference_truth(time, key, _state([0, 2, 4, 40, 42]), max_gap_s=15.0)
    assert period == 2.0
    assert sorted(set(truth.target_id.tolist())) == [0, 1]
    assert truth.scan[truth.target_id == 1].tolist() == [20, 21]  # (40 − 0)/2, (42 − 0)/2
    # nothing between 4 s and 40 s: the gap is not bridged
    assert not np.any((truth.time > 4.0) & (truth.time < 40.0))


def test_reference_against_itself_scores_zero() -> None:
    rng = np.random.default_rng(3)
    n = 60
    time = np.sort(rng.uniform(0, 100, n))
    key = rng.integers(0, 4, n)
    state = rng.normal(0, 1e4, (n, 4))
    truth, period = reference_truth(time, key, state, max_gap_s=200.0)
    # our "tracks" are the reference's own updates
    tracks = TrackTable(scan=np.arange(n), time=time, track_id=key, x=state[:, 0],
                        y=state[:, 1], vx=state[:, 2], vy=state[:, 3],
                        plot=np.full(n, -1)).sorted()
    ours = tracks_at_reference(tracks, truth, period, max_gap_s=200.0)
    assert np.array_equal(ours.scan, truth.scan) and np.array_equal(ours.x, truth.x)
    ev, _, _ = evaluate_reference(tracks, time, key, state, max_gap_s=200.0)
    assert ev.ospa_mean == 0.0 and ev.clear_mot.mota == 1.0
    assert ev.clear_mot.id_switches == 0


# --- the property: our tracks, exported as CAT062, read back as the reference -----------

pytest.importorskip("asterix.generated", reason="libasterix not installed")

ORIGIN = (48.0, 11.0)


def _write_tracks(path: Path, tracks: list[tuple[float, float, float, float, int, int]]
                  ) -> None:
    """Straight tracks ``(x0, y0, vx, vy, first tick, ticks)`` in the plane about
    ``ORIGIN``, one row every 2 s (in 1/128 s ticks: times exact in I062/070) with a
    jitter of whole ticks, written with ``lat, lon`` and east/north velocities."""
    from mhtrack.models.geodesy import LocalFrame

    frame = LocalFrame(*ORIGIN)
    rows = []
    for tid, (x0, y0, vx, vy, first, n) in enumerate(tracks):
        ticks = first + np.arange(n) * 256 + (np.arange(n) * 37 % 11)
        t = ticks / 128.0
        x, y = x0 + vx * (t - t[0]), y0 + vy * (t - t[0])
        lat, lon = frame.to_geodetic(x, y)
        ve, vn = frame.velocity_to_geodetic(x, y, np.full(n, vx), np.full(n, vy))
        rows += [(t[i], tid, lat[i], lon[i], ve[i], vn[i]) for i in range(n)]
    rows.sort()
    path.write_text("frame,time,track_id,lat,lon,vx,vy,plot\n" + "".join(
        f"{i}," + ",".join(repr(float(v)) if k != 1 else str(v) for k, v in enumerate(r))
        + ",\n" for i, r in enumerate(rows)))


@settings(max_examples=12, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.tuples(st.floats(-1e5, 1e5), st.floats(-1e5, 1e5),
                          st.floats(-300, 300), st.floats(-300, 300),
                          st.integers(0, 3000), st.integers(2, 30)),
                min_size=1, max_size=8))
def test_own_tracks_as_cat062_reference_score_as_themselves(
        tmp_path: Path, tracks: list[tuple[float, float, float, float, int, int]]) -> None:
    """Whatever the tracks, exported as CAT062 and taken as the reference they match
    themselves: every reference state matched, none false, no identity switch, one
    reference target per track, and positions within the I062/105 LSB (180/2²⁵°)."""
    from mhtrack.io import read_tracks
    from mhtrack.io.asterix.cat062 import lsb062
    from mhtrack.io.asterix.cat062_export import export_tracks
    from mhtrack.io.reference import read_reference

    csv, ast = tmp_path / "tracks.csv", tmp_path / "ref.ast"
    _write_tracks(csv, tracks)
    export_tracks(csv, None, ast)
    ref = read_reference(ast)
    assert not ref.problems.counts
    ours = read_tracks(csv, frame=ref.frame, geodetic=True, accept_truth=False)
    ev, _, _ = evaluate_reference(ours, ref.time, ref.key, ref.state, max_gap_s=15.0)
    m = ev.clear_mot
    assert m.n_misses == 0 and m.n_false == 0 and m.id_switches == 0
    assert ev.n_targets == ev.n_tracks == len(tracks)
    lsb_m = lsb062()["deg"] * 111_320.0  # one LSB of latitude, in metres
    assert m.motp <= lsb_m
    assert ev.coverage == 1.0


def test_adsb_reports_as_the_reference(tmp_path: Path) -> None:
    """A recording with CAT021 ADS-B reports and no CAT062 is read as the aircraft's own
    reports: one reference target per address, a report flagged simulated and one with
    no identity left out and counted at their blocks; tracks on the same straight lines
    match it with no miss, false track or switch (positions within the I021/131 LSB)."""
    from mhtrack.io import read_tracks
    from mhtrack.io.asterix import encode_other
    from mhtrack.io.reference import read_reference
    from mhtrack.models.geodesy import LocalFrame

    station = 0x0709
    tracks = [(-2e4, 1e4, 150.0, -40.0, 0, 30), (3e4, -5e3, -90.0, 120.0, 100, 30)]
    csv = tmp_path / "tracks.csv"
    _write_tracks(csv, tracks)
    frame = LocalFrame(*ORIGIN)
    blocks = []
    for k, (x0, y0, vx, vy, first, n) in enumerate(tracks):
        t = (first + np.arange(n) * 256 + (np.arange(n) * 37 % 11)) / 128.0
        lat, lon = frame.to_geodetic(x0 + vx * (t - t[0]), y0 + vy * (t - t[0]))
        blocks += [(float(t[i]), encode_other.report021(
            float(t[i]), station, float(lat[i]), float(lon[i]), address=f"{0xA00000 + k:06X}"))
            for i in range(n)]
    lat0, lon0 = frame.to_geodetic(np.array([0.0]), np.array([0.0]))
    bad = [(5.0, encode_other.report021(5.0, station, float(lat0[0]), float(lon0[0]),
                                        address="ABCDEF", sim=1)),
           (6.0, encode_other.report021(6.0, station, float(lat0[0]), float(lon0[0])))]
    reports = sorted(blocks + bad, key=lambda b: b[0])
    ast = tmp_path / "adsb.ast"
    ast.write_bytes(b"".join(b for t, r in reports
                             for _, _, b in encode_other.blocks([(t, station, 21, r)])))
    ref = read_reference(ast, frame)
    assert sorted(set(ref.key.tolist())) == [0xA00000, 0xA00001]
    assert len(ref) == 60
    assert ref.problems.counts == {"not_plot": 1, "no_identity": 1}
    ours = read_tracks(csv, frame=frame, geodetic=True, accept_truth=False)
    ev, _, _ = evaluate_reference(ours, ref.time, ref.key, ref.state, max_gap_s=15.0)
    m = ev.clear_mot
    assert m.n_misses == 0 and m.n_false == 0 and m.id_switches == 0
    assert ev.n_targets == 2
    assert m.motp <= 180.0 / 2**30 * 111_320.0 * 2  # I021/131: 180/2³⁰ ° a step


def test_adsb_reference_is_walked_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                                       ) -> None:
    """A recording with no CAT062 is read as CAT021 from the same walk of the file (the
    framing reader runs once), with the same updates and problems as a walk of its own
    for CAT021 (the former path)."""
    from mhtrack.io.asterix import encode_other
    from mhtrack.io.asterix.decode import Decoder
    from mhtrack.io.reference import _adsb_reports, read_reference
    from mhtrack.models.geodesy import LocalFrame

    frame = LocalFrame(*ORIGIN)
    lat, lon = frame.to_geodetic(np.linspace(0, 9e3, 10), np.zeros(10))
    reports = [(t, encode_other.report021(t, 0x0709, float(lat[i]), float(lon[i]),
                                          address="A00001"))
               for i, t in enumerate(np.arange(10) * 4.0)]
    ast = tmp_path / "adsb.ast"
    ast.write_bytes(b"".join(b for t, r in reports
                             for _, _, b in encode_other.blocks([(t, 0x0709, 21, r)]))
                    + b"\x15\x00")  # two octets of damage at the end
    walks = []
    real = Decoder.units  # the one reading path of a recording (category_file's too)
    monkeypatch.setattr(Decoder, "units",
                        lambda self, *a, **k: walks.append(1) or real(self, *a, **k))
    ref = read_reference(ast, frame)
    assert len(walks) == 1 and len(ref) == 10
    cols, key, problems = _adsb_reports(ast)
    assert np.array_equal(ref.time, cols["time"]) and np.array_equal(ref.key, key)
    assert ref.problems == problems and problems.counts == {"resync": 1,
                                                            "skipped_octets": 2}
