"""export then convert gives the plots back within one LSB of each item (simulated
opensky-radars plots, three rotating radars), across midnight too."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow.csv as pacsv
import pytest

from mhtrack.io.asterix import convert, export, read_recording
from mhtrack.io.asterix.encode import lsb
from mhtrack.io.asterix.timeaxis import unwrap_days
from mhtrack.io.sensors import read_sensors


def _table(path: Path) -> dict[str, np.ndarray]:
    t = pacsv.read_csv(path)
    return {n: t.column(n).to_numpy(zero_copy_only=False) for n in t.column_names}


@pytest.mark.parametrize("suffix", [".pcap", ".ast"])
def test_export_convert_equals_plots(opensky: Path, opensky_head: Path, tmp_path: Path,
                                     suffix: str) -> None:
    sensors = read_sensors(opensky / "sensors.toml")
    rec_path = tmp_path / f"rec{suffix}"
    n, _ = export(opensky_head, sensors, rec_path)
    assert n == 3000
    out = tmp_path / "back.csv"
    convert(rec_path, out, sensors)
    a, b = _table(opensky_head), _table(out)
    L = lsb()
    assert np.array_equal(a["sensor"], b["sensor"])  # same plots, same order
    assert np.abs(a["time"] - b["time"]).max() <= L["tod_s"] / 2 + 1e-9
    assert np.abs(a["range"] - b["range"]).max() <= L["rho_nm"] * 1852.0 / 2 + 1e-6
    db = np.abs((a["bearing"] - b["bearing"] + 180.0) % 360.0 - 180.0)
    assert db.max() <= L["theta_deg"] / 2 + 1e-9
    assert np.array_equal(b["sac"] * 256 + b["sic"], b["sensor"])


def test_north_markers_give_the_periods(opensky: Path, opensky_head: Path,
                                        tmp_path: Path) -> None:
    sensors = read_sensors(opensky / "sensors.toml")
    export(opensky_head, sensors, tmp_path / "rec.ast")
    rec = read_recording(tmp_path / "rec.ast")
    assert rec.periods() == {s.id: s.period for s in sensors.sensors}
    north = rec.sweeps["kind"] == 1
    crossing = rec.sweeps["azimuth"][~north]
    assert set(np.round(crossing, 6).tolist()) == {45.0 * k for k in range(1, 8)}


def test_midnight_rollover(opensky: Path, tmp_path: Path) -> None:
    sensors = read_sensors(opensky / "sensors.toml")
    plots = tmp_path / "midnight.csv"
    t = 86390.0 + np.arange(40) * 0.5  # 23:59:50 to 00:00:09.5
    rows = "\n".join(f"{x},1,{1e5 + 100 * i},{(9 * i) % 360}" for i, x in enumerate(t))
    plots.write_text("time,sensor,range,bearing\n" + rows + "\n")
    export(plots, sensors, tmp_path / "m.ast")
    convert(tmp_path / "m.ast", tmp_path / "m.csv")
    back = _table(tmp_path / "m.csv")["time"]
    assert np.abs(back - t).max() <= lsb()["tod_s"] / 2  # past 86 400 s, not back to 0
    assert back.max() > 86400.0


def test_unwrap_days_keeps_jitter() -> None:
    tod = np.array([86399.0, 86399.9, 0.2, 86399.95, 0.5, 10.0])
    assert np.allclose(unwrap_days(tod), [86399.0, 86399.9, 86400.2, 86399.95, 86400.5,
                                          86410.0])
