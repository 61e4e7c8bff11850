"""Plot attributes through ASTERIX: simulated opensky-radars plots with codes, levels,
addresses and garbling, exported as CAT048, read back item by item with libasterix alone
(the independent decoder), by mhtrack's decoder (fast and reference paths) and by the
recording source the tracker reads."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import mhtrack.io.asterix._lib as _lib
from mhtrack.attributes import COMBINED, MODE_S, PRIMARY, code_text
from mhtrack.io import read_plots
from mhtrack.io.asterix import export, read_recording
from mhtrack.io.asterix.container import blocks
from mhtrack.io.asterix.framings import recognise, units
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.sensors import read_sensors
from mhtrack.sources import open_source


@pytest.fixture(scope="module")
def attributed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``simulate opensky-radars --scans 10 --attributes --garble 0.3`` and its export."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    out = tmp_path_factory.mktemp("attrs")
    r = CliRunner().invoke(cli, ["simulate", "opensky-radars", "--seed", "2", "--scans",
                                 "10", "--attributes", "--garble", "0.3", "--out", str(out)])
    assert r.exit_code == 0, r.output
    export(out / "plots.csv", read_sensors(out / "sensors.toml"), out / "rec.pcap")
    return out


def _libasterix_items(path: Path) -> list[dict[str, object]]:
    """Every CAT048 record's attribute items, decoded by libasterix's own item API."""
    base = _lib.modules()[0]
    data = path.read_bytes()
    kind = recognise(data, str(path), {34, 48})
    out = []
    for offset, _, payload in units(data, kind, str(path), {34, 48}, Problems()):
        for _, cat, raw in blocks(payload, offset, Problems()):
            if cat != 48:
                continue
            for rec in _lib.cat048().cv_uap.parse(base.Bits.from_bytes(raw)):
                row: dict[str, object] = {}
                i020 = rec.get_item("020")
                row["typ"] = i020.variation.get_item("TYP").variation.content.as_uint()
                if (i070 := rec.get_item("070")) is not None:
                    v = i070.variation
                    row["code"] = v.get_item("MODE3A").variation.content.as_string()
                    row["code_vg"] = (v.get_item("V").variation.content.as_uint(),
                                      v.get_item("G").variation.content.as_uint())
                if (i090 := rec.get_item("090")) is not None:
                    v = i090.variation
                    row["fl"] = float(v.get_item("FL").variation.content.as_quantity("FL"))
                    row["fl_vg"] = (v.get_item("V").variation.content.as_uint(),
                                    v.get_item("G").variation.content.as_uint())
                if (i220 := rec.get_item("220")) is not None:
                    row["address"] = i220.variation.content.as_uint()
                if (i240 := rec.get_item("240")) is not None:
                    row["callsign"] = i240.variation.content.as_string().strip()
                out.append(row)
    return out


def test_libasterix_reads_what_was_written(attributed: Path) -> None:
    plots = read_plots(attributed / "plots.csv", read_sensors(attributed / "sensors.toml"))
    a = plots.attrs
    assert a is not None and (a.mode_3a_g == 1).any() and (a.plot_type == PRIMARY).any()
    # the export writes in file order: the table's rows by file row
    order = np.argsort(plots.file_row)
    got = _libasterix_items(attributed / "rec.pcap")
    assert len(got) == len(plots)
    typ = {1: PRIMARY, 2: 2, 3: COMBINED, 5: MODE_S}
    for i, row in zip(order.tolist(), got, strict=True):
        assert typ[row["typ"]] == a.plot_type[i]
        if a.mode_3a[i] >= 0:
            assert row["code"] == code_text(a.mode_3a[i])
            assert row["code_vg"] == (a.mode_3a_v[i], a.mode_3a_g[i])
        else:
            assert "code" not in row
        if np.isfinite(a.flight_level[i]):
            assert abs(row["fl"] - a.flight_level[i]) <= 0.125  # half the 1/4 FL LSB
            assert row["fl_vg"] == (a.flight_level_v[i], a.flight_level_g[i])
        else:
            assert "fl" not in row
        assert row.get("address", -1) == a.address[i]
        assert row.get("callsign", "") == a.callsign[i]


@pytest.mark.parametrize("fast", [True, False])
def test_decoder_and_source_give_the_attributes_back(attributed: Path, fast: bool) -> None:
    sensors = read_sensors(attributed / "sensors.toml")
    plots = read_plots(attributed / "plots.csv", sensors)
    want = plots.attrs.take(np.argsort(plots.file_row))  # file order = decoding order
    rec = read_recording(attributed / "rec.pcap", fast=fast)
    assert rec.plots["mode_3a"].tolist() == [code_text(v) for v in want.mode_3a.tolist()]
    vg = 2 * want.mode_3a_v + want.mode_3a_g
    assert np.array_equal(rec.plots["mode_3a_vg"], vg)
    assert np.array_equal(rec.plots["flight_level_vg"],
                          2 * want.flight_level_v + want.flight_level_g)
    # the recording source: each frame's Scan.attrs, back to the decoding order
    src = open_source(attributed / "rec.pcap", sensors=sensors)
    rows, parts = [], []
    for scan in src:
        rows.append(src.file_rows(scan.rows))
        parts.append(scan.attrs)
    back = type(want).concat(parts).take(np.argsort(np.concatenate(rows)))
    for name, v in want.columns().items():
        w = getattr(back, name)
        if name == "flight_level":
            np.testing.assert_allclose(w, v, atol=0.125)
        else:
            assert np.array_equal(w, v, equal_nan=w.dtype.kind == "f"), name
    # the plot's measured position (I062/340 POS of the tracks): I048/040 as decoded —
    # the slant range, and the plots file's bearing within THETA's LSB
    assert np.array_equal(back.polar_range, rec.plots["slant_range"])
    # ... the same slant range the plots file's ground range gives at the plot's flight
    # level (io.plot_attributes: NaN without one), within RHO's 1/256 NM LSB
    level = np.isfinite(want.flight_level)
    assert level.any() and np.isnan(want.polar_range[~level]).all()
    np.testing.assert_allclose(back.polar_range[level], want.polar_range[level],
                               atol=1852.0 / 256 / 2 + 1e-6)
    d = (back.polar_bearing - want.polar_bearing + 180.0) % 360.0 - 180.0
    assert np.abs(d).max() <= 360.0 / 2**16 / 2 + 1e-9
