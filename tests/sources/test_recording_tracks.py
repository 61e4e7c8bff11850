"""Issue 27's acceptance at the level of the tracks: a recording spanning 23:59 → 00:01 UTC,
and one with a 13-hour gap, tracked by ``mhtrack track`` give monotonic times and the
tracks of the unshifted recording (``test_recordings.py`` checks the same at the level of
the frames).

Why the comparison is exact (no tolerance): CAT048 times of day (I048/140) are counted in
units of 2⁻⁷ s, so every plot time is ``k/128`` with ``k < 86 400·128 < 2²⁴``. Such a time
plus 86 340 s or 46 800 s (integers below 2¹⁷) needs at most 24 significant bits, far
within float64's 53: the sum is exact, and so is every time difference the tracker forms
from shifted times. The tracker sees the same numbers, so its tracks are the same bit for
bit and only the time column moves, by exactly the shift. (Times not on a 2⁻⁷ s grid would
round: near 86 400 s the spacing of float64 is 2⁻³⁶ s ≈ 1.5·10⁻¹¹ s, and a state moving at
300 m/s would then differ by ~10⁻⁸ m per step; a tolerance would be needed there, and
would hide a real difference here.)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow.csv as pacsv
import pytest
from click.testing import CliRunner

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from mhtrack.cli.main import cli
from mhtrack.io.asterix import export
from mhtrack.io.sensors import read_sensors

from .test_recordings import PCAP_HEAD, _shifted_csv

MIDNIGHT = 86340.0  # the two minutes moved to 23:59:00 → 00:00:50 UTC
GAP = 46800.0  # 13 hours: more than half a day forward


def _track(path: Path, sensors: Path) -> dict[str, np.ndarray]:
    """``mhtrack track PATH --sensors SENSORS --out …``: the tracks file's columns."""
    out = path.with_suffix(".tracks.csv")
    r = CliRunner().invoke(cli, ["track", str(path), "--sensors", str(sensors),
                                 "--out", str(out)])
    assert r.exit_code == 0, r.output
    table = pacsv.read_csv(out)
    return {k: table[k].to_numpy(zero_copy_only=False) for k in table.column_names}


def _same_tracks(ref: dict[str, np.ndarray], got: dict[str, np.ndarray], shift: float,
                 shift_from: float) -> None:
    """``got`` equals ``ref`` in every column, bit for bit, but ``time``, which is
    ``ref``'s plus ``shift`` from ``shift_from`` on; and ``got``'s frames are in order."""
    assert list(got) == list(ref)
    assert len(got["time"]) == len(ref["time"]) > 500
    want = np.where(ref["time"] >= shift_from, ref["time"] + shift, ref["time"])
    assert np.array_equal(got["time"], want)
    for name in ref:
        if name != "time":
            assert np.array_equal(got[name], ref[name], equal_nan=True), name
    assert np.all(np.diff(got["frame"]) >= 0)


def test_midnight_tracks(opensky2: Path, tmp_path: Path) -> None:
    """23:59:00 → 00:00:50 UTC: the tracks of the recording at 00:00, times + 86 340 s."""
    sensors = opensky2 / "sensors.toml"
    export(opensky2 / "plots.csv", read_sensors(sensors), tmp_path / "rec.pcap")
    late = _shifted_csv(opensky2 / "plots.csv", tmp_path / "m.csv", lambda t: True,
                        lambda t: MIDNIGHT)
    export(late, read_sensors(sensors), tmp_path / "midnight.pcap")
    ref = _track(tmp_path / "rec.pcap", sensors)
    got = _track(tmp_path / "midnight.pcap", sensors)
    _same_tracks(ref, got, MIDNIGHT, 0.0)
    # past midnight on one axis: nothing wrapped back to the small hours
    assert got["time"].min() >= MIDNIGHT and got["time"].max() > 86400.0


def test_13_hour_gap_tracks(opensky2: Path, tmp_path: Path) -> None:
    """Plots before 50 s, then (after 5 quiet seconds) the rest 13 h later, as one
    recording: the tracks of the recording without the gap (``q``) decoded into a plots
    table (``mhtrack convert``) whose later times are moved by 13 h by hand — the gap put
    in explicitly, where the recording's must be inferred from its times of day."""
    sensors = opensky2 / "sensors.toml"
    radars = read_sensors(sensors)
    src = opensky2 / "plots.csv"
    quiet = _shifted_csv(src, tmp_path / "q.csv", lambda t: not 50.0 <= t < 55.0,
                         lambda t: 0.0)
    export(quiet, radars, tmp_path / "q.pcap")
    parts = []
    for name, keep, shift in (("a", lambda t: t < 50.0, 0.0),
                              ("b", lambda t: t >= 55.0, GAP)):
        part = _shifted_csv(src, tmp_path / f"{name}.csv", keep, lambda t, s=shift: s)
        export(part, radars, tmp_path / f"{name}.pcap")
        parts.append((tmp_path / f"{name}.pcap").read_bytes())
    (tmp_path / "gap.pcap").write_bytes(parts[0] + parts[1][PCAP_HEAD:])

    r = CliRunner().invoke(cli, ["convert", str(tmp_path / "q.pcap"),
                                 str(tmp_path / "q_plots.csv"), "--sensors", str(sensors)])
    assert r.exit_code == 0, r.output
    # the plots table with the gap put in by hand (k/128 + 46 800 is exact, see above)
    table = _shifted_csv(tmp_path / "q_plots.csv", tmp_path / "gap_plots.csv",
                         lambda t: True, lambda t: GAP if t >= 55.0 else 0.0)
    ref = _track(table, sensors)
    got = _track(tmp_path / "gap.pcap", sensors)
    _same_tracks(ref, got, 0.0, np.inf)  # the table's times are already shifted
    assert got["time"].min() < 50.0 and got["time"].max() > GAP
