"""``convert`` writes CAT021 ADS-B reports to the plots table (issue 28, deliverable 2):
rows of the station (a sensor of kind ``adsb``) in file order beside the radar's plots,
with their WGS-84 position and its σ from NACp — our own encoder's reports back within
one LSB, as pyasteryx (an independent decoder) reads them — and the table tracked as
timed plots places each report at its position with its own σ."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow.csv as pacsv
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from mhtrack.errors import InputError
from mhtrack.io.asterix import cat021, encode_other
from mhtrack.io.asterix.api import convert
from mhtrack.io.asterix.encode import encode_blocks, plot_messages
from mhtrack.io.timed_plots import read_timed_plots
from mhtrack.models.radars import RadarSensor, SensorSet

RADAR, STATION = 0x0102, 0x0709
LAT_LSB = 180.0 / 2**30  # I021/131


def _recording(path: Path, nacp: np.ndarray) -> dict[str, np.ndarray]:
    """CAT048 plots of one radar and CAT021 reports of one station, a data block each,
    interleaved in time; the reports' encoded values."""
    rng = np.random.default_rng(5)
    n = nacp.size
    t_plot = np.arange(20) * 0.5 + 1000.0
    msgs = plot_messages(t_plot, np.full(20, RADAR), rng.uniform(1e4, 2e5, 20),
                         rng.uniform(0, 360, 20), {})
    radar = [(t, b) for m in msgs for t, _, b in encode_blocks([m])]
    a = {"time": np.sort(rng.uniform(1000.0, 1010.0, n)), "lat": rng.uniform(50, 52, n),
         "lon": rng.uniform(3, 6, n), "fl": np.round(rng.uniform(10, 400, n)), "nacp": nacp}
    reports = [(t, b) for i in range(n) for t, _, b in encode_other.blocks([(
        float(a["time"][i]), STATION, 21, encode_other.report021(
            float(a["time"][i]), STATION, float(a["lat"][i]), float(a["lon"][i]),
            nacp=int(nacp[i]), fl=float(a["fl"][i]), address=f"{0xABC000 + i:06X}"))])]
    both = sorted(radar + reports, key=lambda x: x[0])
    path.write_bytes(b"".join(b for _, b in both))
    a["is_adsb"] = np.array([any(b is r for _, r in reports) for _, b in both])
    return a


def _sensors() -> SensorSet:
    return SensorSet(None, (
        RadarSensor(RADAR, "polar", pd=0.9, lat=51.0, lon=4.5, alt=30.0, sigma_range=50.0,
                    sigma_bearing_deg=0.1),
        RadarSensor(STATION, "adsb", pd=0.95)))


def test_adsb_reports_are_rows_of_the_table(tmp_path: Path) -> None:
    nacp = np.array([9, 10, 8, 11, 7, 0, 9, 10])
    a = _recording(tmp_path / "rec.ast", nacp)
    convert(tmp_path / "rec.ast", tmp_path / "p.csv", _sensors())
    t = pacsv.read_csv(tmp_path / "p.csv").to_pydict()
    kind = np.array(t["plot_type"])
    assert (kind == "adsb").tolist() == a["is_adsb"].tolist()  # file order, all kept
    adsb = kind == "adsb"
    sensor = np.array(t["sensor"])
    assert set(sensor[adsb].tolist()) == {STATION} and set(sensor[~adsb]) == {RADAR}

    def col(name: str) -> np.ndarray:
        return np.array([np.nan if v is None else v for v in t[name]], float)

    assert np.abs(col("lat")[adsb] - a["lat"]).max() <= LAT_LSB
    assert np.abs(col("lon")[adsb] - a["lon"]).max() <= LAT_LSB
    assert np.abs(col("time")[adsb] - a["time"]).max() <= 1 / 128
    assert np.array_equal(col("flight_level")[adsb], a["fl"])
    want = np.array([cat021.sigma_m(int(k), 0, 2) for k in nacp])
    assert np.allclose(col("sigma")[adsb], want, equal_nan=True, rtol=1e-12)
    assert np.isnan(want[5])  # NACp 0: no accuracy, an empty cell
    for name in ("lat", "lon", "sigma"):  # the radar's rows leave them empty
        assert np.isnan(col(name)[~adsb]).all()
    for name in ("slant_range", "bearing", "range"):  # the station measures no polar
        assert np.isnan(col(name)[adsb]).all()
    assert t["address"][int(np.flatnonzero(adsb)[0])] == "ABC000"
    pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx not installed")
    ref = [m.items for m in pyasteryx.Decoder().decode((tmp_path / "rec.ast").read_bytes())
           if "I021/131" in m.items]
    assert len(ref) == nacp.size
    assert np.abs(np.array([r["I021/131"]["Lat"] for r in ref]) - col("lat")[adsb]
                  ).max() <= LAT_LSB / 2
    assert np.abs(np.array([r["I021/131"]["Lon"] for r in ref]) - col("lon")[adsb]
                  ).max() <= LAT_LSB / 2


def test_converted_table_tracked_with_each_reports_sigma(tmp_path: Path) -> None:
    """Read back as timed plots: each report at ``frame.to_local(lat, lon)`` with ``R =
    σ² I`` (its own σ); a report without one is refused, naming its row, until the
    sensors file gives the station a ``sigma``."""
    nacp = np.array([9, 10, 8, 11, 0, 7])
    _recording(tmp_path / "rec.ast", nacp)
    sensors = _sensors()
    convert(tmp_path / "rec.ast", tmp_path / "p.csv", sensors)
    with pytest.raises(InputError, match=r"sigma.*no accuracy: sensor 1801 is an ADS-B"):
        read_timed_plots(tmp_path / "p.csv", sensors)
    fallback = SensorSet(None, (sensors.sensors[0], RadarSensor(STATION, "adsb", pd=0.95,
                                                                sigma=77.0)))
    plots = read_timed_plots(tmp_path / "p.csv", fallback)
    t = pacsv.read_csv(tmp_path / "p.csv").to_pydict()
    rows = np.flatnonzero(np.array(t["plot_type"]) == "adsb")
    lat = np.array([t["lat"][r] for r in rows], float)
    lon = np.array([t["lon"][r] for r in rows], float)
    x, y = fallback.frame().to_local(lat, lon)
    at = np.array([int(np.flatnonzero(plots.file_row == r)[0]) for r in rows])
    assert np.allclose(plots.z[at], np.column_stack((x, y)), atol=1e-6)
    sigma = np.array([cat021.sigma_m(int(k), 0, 2) if k else 77.0 for k in nacp])
    assert np.allclose(plots.R[at][:, 0, 0], sigma**2) and np.all(plots.R[at][:, 0, 1] == 0)
