"""The fast CAT048/CAT034 path (layouts learnt from libasterix, needed fields read with
libasterix's LSBs) gives exactly what libasterix alone gives."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mhtrack.io.asterix import _lib, export, read_recording
from mhtrack.io.asterix.encode import lsb
from mhtrack.io.asterix.fast import field
from mhtrack.io.sensors import read_sensors


def _same(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> None:
    assert a.keys() == b.keys()
    for k in a:
        if a[k].dtype.kind == "f":
            assert np.array_equal(a[k], b[k], equal_nan=True), k
        else:
            assert np.array_equal(a[k], b[k]), k


def _both(path: Path) -> None:
    fast, slow = read_recording(path), read_recording(path, fast=False)
    _same(fast.plots, slow.plots)
    _same(fast.sweeps, slow.sweeps)
    assert fast.problems.counts == slow.problems.counts
    assert fast.problems.first == slow.problems.first


def test_conformance_recording(conformance_pcap: Path) -> None:
    _both(conformance_pcap)


def test_exported_and_damaged(opensky: Path, opensky_head: Path, tmp_path: Path) -> None:
    sensors = read_sensors(opensky / "sensors.toml")
    path = tmp_path / "rec.ast"
    export(opensky_head, sensors, path)
    _both(path)
    data = bytearray(path.read_bytes())
    at = 0  # shorten the length field of data block 300 by one octet
    for k in range(400):
        length = int.from_bytes(data[at + 1:at + 3], "big")
        if k == 300:
            data[at + 1:at + 3] = (length - 1).to_bytes(2, "big")
            break
        at += length
    (tmp_path / "bad.ast").write_bytes(bytes(data))
    assert read_recording(tmp_path / "bad.ast").problems.counts  # damage was seen
    _both(tmp_path / "bad.ast")


def test_fields_from_libasterix_spec() -> None:
    rec = _lib.cat048().cv_record
    rho = field(rec, "040", "RHO")
    theta = field(rec, "040", "THETA")
    assert (rho.nbytes, rho.offset, rho.size, rho.lsb) == (4, 0, 16, lsb()["rho_nm"])
    assert (theta.offset, theta.size, theta.lsb) == (16, 16, lsb()["theta_deg"])
    fl = field(rec, "090", "FL")
    assert (fl.offset, fl.size, fl.signed) == (2, 14, True)
    assert fl.read(bytes([0x3F, 0xFF]), 0) == pytest.approx(-0.25)  # two's complement
    assert field(rec, "140").lsb == lsb()["tod_s"]
