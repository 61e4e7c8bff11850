"""Conformance on a real recording: cat_034_048.pcap (asterix_decoder 0.7.11 sample data)
decoded by mhtrack (libasterix) and by an independent decoder, pyasteryx (its own
spec tables, its own pcap reader), plot for plot within one LSB."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mhtrack.io.asterix import read_recording
from mhtrack.io.asterix.encode import lsb

SICS = {11, 12, 13, 14, 201, 204, 205}


def test_126_plots_from_seven_radars(conformance_pcap: Path) -> None:
    rec = read_recording(conformance_pcap)
    assert rec.container == "pcap"
    assert len(rec) == 126
    assert set(rec.plots["sac"].tolist()) == {25}
    assert set(rec.plots["sic"].tolist()) == SICS
    assert np.array_equal(rec.plots["sensor"], 25 * 256 + rec.plots["sic"])
    # two CAT048 reports of the file have no I048/040: counted, not plots
    assert rec.problems.counts == {"no_position": 2}
    assert rec.sweeps["time"].size > 0  # the CAT034 sector crossings are read
    assert set(rec.sweeps["kind"].tolist()) <= {1, 2}


def test_every_plot_matches_pyasteryx(conformance_pcap: Path) -> None:
    pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx (extra [reference]) "
                                    "not installed")
    decoder = pyasteryx.Decoder(on_error="skip")  # it has no CAT034: those blocks skipped
    ref = [m.items for m in decoder.decode_pcap(str(conformance_pcap))
           if m.category == 48 and "I048/040" in m.items]
    rec = read_recording(conformance_pcap)
    p = rec.plots
    assert len(ref) == len(rec) == 126
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
