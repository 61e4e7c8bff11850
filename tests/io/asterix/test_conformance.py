"""Conformance on a real recording: cat_034_048.pcap (asterix_decoder 0.7.11 sample data,
a capture of two redundant LANs: every data block twice) decoded by mhtrack (libasterix)
and by an independent decoder, pyasteryx (its own spec tables, its own pcap reader), plot
for plot within one LSB; tracked without a sensors file from the one radar that sends
its site in CAT034."""

from __future__ import annotations

import logging
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mhtrack.io.asterix import read_recording
from mhtrack.io.asterix.encode import lsb
from mhtrack.io.sensors import read_sensors, write_sensors
from mhtrack.models.radars import RadarSensor, SensorSet

SICS = {11, 12, 13, 14, 201, 204, 205}


def test_63_distinct_plots_from_seven_radars(conformance_pcap: Path) -> None:
    rec = read_recording(conformance_pcap)
    assert rec.container == "pcap"
    assert len(rec) == 63
    assert set(rec.plots["sac"].tolist()) == {25}
    assert set(rec.plots["sic"].tolist()) == SICS
    assert np.array_equal(rec.plots["sensor"], 25 * 256 + rec.plots["sic"])
    # 60 of the 120 data blocks arrived again on the second LAN; one CAT048 report (twice
    # in the file) has no I048/040: counted, not a plot
    assert rec.problems.counts == {"duplicate": 60, "no_position": 1}
    assert rec.sweeps["time"].size > 0  # the CAT034 sector crossings are read
    assert set(rec.sweeps["kind"].tolist()) <= {1, 2}
    assert list(rec.sites) == [25 * 256 + 12]  # only SIC 12 sends I034/120


def _distinct(items: list[dict]) -> list[dict]:
    """Each report once, in the order first received."""
    out, seen = [], set()
    for r in items:
        key = repr(sorted(r.items()))
        if key not in seen:
            seen.add(key)
            out.append(r)
    return out


def test_every_plot_matches_pyasteryx(conformance_pcap: Path) -> None:
    pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx (extra [reference]) "
                                    "not installed")
    decoder = pyasteryx.Decoder(on_error="skip")  # it has no CAT034: those blocks skipped
    every = [m.items for m in decoder.decode_pcap(str(conformance_pcap))
             if m.category == 48 and "I048/040" in m.items]
    ref = _distinct(every)
    rec = read_recording(conformance_pcap)
    p = rec.plots
    assert len(every) == 126 and len(ref) == len(rec) == 63
    L = lsb()
    t = np.array([r["I048/140"]["ToD"] for r in ref])
    sensor = np.array([r["I048/010"]["SAC"] * 256 + r["I048/010"]["SIC"] for r in ref])
    rho = np.array([r["I048/040"]["RHO"] for r in ref]) * 1852.0
    theta = np.array([r["I048/040"]["THETA"] for r in ref])
    assert np.array_equal(p["sensor"], sensor)
    assert np.abs(p["time"] - t).max() <= L["tod_s"]
    assert np.abs(p["slant_range"] - rho).max() <= L["rho_nm"] * 1852.0
    assert np.abs(p["bearing"] - theta).max() <= L["theta_deg"]
    fl = np.array([r.get("I048/090", {}).get("FL", np.nan) for r in ref])
    assert np.array_equal(np.isnan(p["flight_level"]), np.isnan(fl))
    ok = ~np.isnan(fl)
    assert np.abs(p["flight_level"][ok] - fl[ok]).max() <= L["fl"]
    m3a = [r.get("I048/070", {}).get("Mode3A", "") for r in ref]
    assert p["mode_3a"].tolist() == m3a
    tn = [r.get("I048/161", {}).get("Tn", -1) for r in ref]
    assert p["track_number"].tolist() == tn
    typ = [r["I048/020"]["TYP"] for r in ref]
    assert p["typ"].tolist() == typ
    # plot type by CAT048 ed. 1.32's TYP table: 5 single Mode S roll-call -> Mode S (4),
    # 3 SSR + PSR and 7 Mode S roll-call + PSR -> combined (3)
    assert p["plot_type"].tolist() == [{3: 3, 5: 4, 7: 3}[k] for k in typ]


def test_tracked_without_a_sensors_file(conformance_pcap: Path,
                                        caplog: pytest.LogCaptureFixture) -> None:
    """Radar SIC 12 at its own I034/120 site; the six others skipped, one warning."""
    from pyproj import Geod

    from mhtrack.sources import open_source

    with caplog.at_level(logging.WARNING, logger="mhtrack"):
        src = open_source(conformance_pcap)
        frames = list(src)
    assert src.sensors is not None and src.sensors.ids == (25 * 256 + 12,)
    radar = src.sensors.sensor(25 * 256 + 12)
    assert (radar.lat, radar.lon, radar.alt) == pytest.approx((43.571026, 16.406064, 780.0),
                                                               abs=1e-6)
    assert radar.period == pytest.approx(4.9453125)  # its I034/041
    rec = read_recording(conformance_pcap)
    mine = rec.plots["sic"] == 12
    assert src.stats.plots_out == int(mine.sum()) == 19
    assert src.stats.skipped["no_site"] == int((~mine).sum())
    assert {int(s) for f in frames for s in f.sensor} == {25 * 256 + 12}
    lines = [r.getMessage() for r in caplog.records if "without a known site" in
             r.getMessage()]
    assert len(lines) == 1 and lines[0].startswith(f"{conformance_pcap}: 6 radar(s)")
    for sic in SICS - {12}:
        assert f"(SAC 25, SIC {sic})" in lines[0]
    # each plot lies at its ground range and bearing from the radar's site
    z = np.concatenate([f.z for f in frames])
    rows = src.file_rows(np.concatenate([f.rows for f in frames]))
    lat, lon = src.sensors.frame().to_geodetic(z[:, 0], z[:, 1])
    az, _, dist = Geod(ellps="WGS84").inv(np.full(z.shape[0], radar.lon),
                                          np.full(z.shape[0], radar.lat), lon, lat)
    assert np.abs((az - rec.plots["bearing"][rows] + 180) % 360 - 180).max() < 1e-6
    assert np.all(dist <= rec.plots["slant_range"][rows])


def _frames(path: Path, sensors: SensorSet):  # type: ignore[no-untyped-def]
    from mhtrack.sources import open_source

    src = open_source(path, sensors=sensors)
    return list(src), src


SIC12 = 25 * 256 + 12
SITE12 = (43.57102632522583, 16.4060640335083)


def test_sensors_file_wins_and_warns_where_the_site_disagrees(
        conformance_pcap: Path, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    radar = RadarSensor(SIC12, "polar", pd=0.9, lat=SITE12[0] + 0.002, lon=SITE12[1],
                        sigma_range=40.0, sigma_bearing_deg=0.05)  # 222 m north
    far = SensorSet(None, (radar,))
    near = SensorSet(None, (replace(radar, lat=SITE12[0] + 0.0005),))  # 56 m north
    for sensors, warned in ((far, True), (near, False)):
        caplog.clear()
        with caplog.at_level(logging.WARNING, logger="mhtrack"):
            frames, src = _frames(conformance_pcap, sensors)
        assert src.sensors.sensor(SIC12).lat == sensors.sensor(SIC12).lat  # the file wins
        assert src.sensors.sensor(SIC12).sigma_range == 40.0 and len(frames) > 0
        lines = [r.getMessage() for r in caplog.records if "I034/120" in r.getMessage()
                 and "sends its site" in r.getMessage()]
        assert len(lines) == int(warned)
        if warned:
            assert lines[0].startswith(f"{conformance_pcap}, byte 2926: radar {SIC12} "
                                       "(SAC 25, SIC 12) sends its site")
            assert " 222 m from the sensors file" in lines[0]


def test_sensors_file_lacking_the_radar_is_filled_from_cat034(
        conformance_pcap: Path, tmp_path: Path) -> None:
    other = RadarSensor(25 * 256 + 11, "polar", pd=0.9, lat=45.0, lon=15.0,
                        sigma_range=40.0, sigma_bearing_deg=0.05)
    write_sensors(SensorSet((44.0, 16.0), (other,)), tmp_path / "one.toml")
    got, src = _frames(conformance_pcap, read_sensors(tmp_path / "one.toml"))
    assert src.sensors.ids == (25 * 256 + 11, SIC12)
    assert src.sensors.origin == (44.0, 16.0)  # the file's frame is kept
    assert (src.sensors.sensor(SIC12).lat, src.sensors.sensor(SIC12).lon) == SITE12
    assert {int(s) for f in got for s in f.sensor} == {25 * 256 + 11, SIC12}
    assert src.stats.skipped["no_site"] == 63 - 19 - 4  # SIC 11 has 4 plots, SIC 12 19


def test_sensors_file_entry_without_a_site_takes_the_radars_own(
        conformance_pcap: Path, tmp_path: Path) -> None:
    """A radar listed with its errors only: the site (and height) from its I034/120, the
    errors from the file."""
    radar = RadarSensor(SIC12, "polar", pd=0.9, sigma_range=40.0, sigma_bearing_deg=0.05)
    write_sensors(SensorSet(None, (radar,)), tmp_path / "errors_only.toml")
    sensors = read_sensors(tmp_path / "errors_only.toml")
    frames, src = _frames(conformance_pcap, sensors)
    got = src.sensors.sensor(SIC12)
    assert (got.lat, got.lon, got.alt) == (*SITE12, 780.0)
    assert (got.sigma_range, got.sigma_bearing_deg, got.pd) == (40.0, 0.05, 0.9)
    assert src.stats.plots_out == 19 and {int(s) for f in frames for s in f.sensor} == {SIC12}
