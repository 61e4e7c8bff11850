"""I048/130 radar plot characteristics (issue 29 item 1, amplitude): CAT048 records built
octet by octet with random subfields, decoded by mhtrack (fast and reference paths)
equal to pyasteryx (an independent decoder) within one LSB; the plot's amplitude is SAM,
else PAM; converted tables carry the columns, and the recording source's plots the
amplitude; a recording without I048/130 has none of them."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.io.asterix import convert, read_recording
from mhtrack.io.asterix.decode import CHARACTERISTICS
from mhtrack.io.sensors import read_sensors

pyasteryx = pytest.importorskip("pyasteryx")

SUB = ("SRL", "SRR", "SAM", "PRL", "PAM", "RPD", "APD")
SIGNED = {"SAM", "PAM", "RPD", "APD"}
#: LSB of each subfield in our units (RPD: 1/256 NM in metres).
LSB = {"SRL": 360 / 2**13, "SRR": 1.0, "SAM": 1.0, "PRL": 360 / 2**13, "PAM": 1.0,
       "RPD": 1852 / 256, "APD": 360 / 2**14}


def _record(tod: float, typ: int, rho_nm: float, theta: float, sub: dict[str, int],
            sic: int = 12) -> bytes:
    """One CAT048 record: FSPEC (010, 140, 020, 040 and 130 when ``sub``), the items'
    octets by hand (EUROCONTROL CAT048 ed. 1.32: 140 1/128 s, 040 1/256 NM and 360/2¹⁶°,
    130 a primary octet SRL…APD, FX then one octet per subfield present)."""
    body = bytes([25, sic]) + round(tod * 128).to_bytes(3, "big") + bytes([typ << 5]) + \
        round(rho_nm * 256).to_bytes(2, "big") + round(theta / 360 * 65536).to_bytes(2, "big")
    if not sub:
        return bytes([0xF0]) + body
    prim = sum(0x80 >> i for i, n in enumerate(SUB) if n in sub)
    return bytes([0xF2]) + body + bytes([prim]) + bytes(sub[n] & 0xFF for n in SUB if n in sub)


def _file(tmp_path, n=300, seed=3, with_130=True):
    rng = np.random.default_rng(seed)
    recs, subs = [], []
    for i in range(n):
        names = [s for s in SUB if rng.random() < 0.5] if with_130 else []
        sub = {s: int(rng.integers(-128, 128) if s in SIGNED else rng.integers(0, 256))
               for s in names}
        recs.append(_record(1000.0 + i * 0.05, int(rng.choice([1, 2, 3, 5])),
                            float(rng.uniform(1, 200)), float(rng.uniform(0, 359)), sub))
        subs.append(sub)
    data = b"".join(recs)
    path = tmp_path / "r.ast"
    path.write_bytes(bytes([48]) + (3 + len(data)).to_bytes(2, "big") + data)
    return path, subs


def _pyasteryx(path):
    """Per record: subfield name → value as pyasteryx decodes it (RPD in NM → m)."""
    out = []
    for m in pyasteryx.Decoder().decode_file(str(path)):
        item = m.items.get("I048/130", {})
        got = {}
        for name in SUB:
            if f"{name}P" in item:
                v = float(item[f"{name}P"][name])
                got[name] = v * 1852 if name == "RPD" else v
        out.append(got)
    return out


@pytest.mark.parametrize("fast", [True, False])
def test_characteristics_equal_pyasteryx(tmp_path, fast):
    path, subs = _file(tmp_path)
    rec = read_recording(path, fast=fast)
    assert len(rec) == len(subs)
    ref = _pyasteryx(path)
    for i, got_ref in enumerate(ref):
        for name, col in zip(SUB, CHARACTERISTICS[:-1], strict=True):
            v = float(rec.plots[col][i])
            if name in got_ref:
                assert abs(v - got_ref[name]) <= LSB[name] / 2 + 1e-9, (i, name, v, got_ref)
            else:
                assert np.isnan(v), (i, name, v)
        sam, pam = got_ref.get("SAM"), got_ref.get("PAM")
        want = sam if sam is not None else pam
        amp = float(rec.plots["amplitude"][i])
        assert (np.isnan(amp) and want is None) or amp == want


def test_raw_values_hand_worked(tmp_path):
    """Two's complement and LSBs by hand: SAM 0xC4 = −60 dBm, RPD 0xFD = −3/256 NM =
    −21.703125 m, APD 5 × 360/2¹⁴ = 0.10986328125°, SRL 10 × 360/2¹³ = 0.439453125°."""
    data = _record(100.0, 5, 50.0, 10.0, {"SRL": 10, "SRR": 4, "SAM": -60, "RPD": -3,
                                          "APD": 5}) + \
        _record(101.0, 1, 60.0, 20.0, {"PRL": 20, "PAM": -70})
    path = tmp_path / "two.ast"
    path.write_bytes(bytes([48]) + (3 + len(data)).to_bytes(2, "big") + data)
    p = read_recording(path).plots
    assert p["srl"].tolist()[0] == 0.439453125 and p["srr"].tolist()[0] == 4.0
    assert p["sam"].tolist()[0] == -60.0 and p["rpd"].tolist()[0] == -21.703125
    assert p["apd"].tolist()[0] == 0.10986328125 and np.isnan(p["pam"][0])
    assert p["prl"].tolist()[1] == 0.87890625 and p["pam"].tolist()[1] == -70.0
    assert p["amplitude"].tolist() == [-60.0, -70.0]


def test_convert_writes_the_columns_and_sources_read_the_amplitude(tmp_path):
    path, _ = _file(tmp_path, n=40)
    sensors = tmp_path / "sensors.toml"
    sensors.write_text('[[sensors]]\nid = 6412\nkind = "polar"\nlat = 50.0\nlon = 8.0\n'
                       'pd = 0.9\nsigma_range = 70.0\nsigma_bearing_deg = 0.08\n')
    out = tmp_path / "plots.csv"
    convert(path, out, sensors=read_sensors(sensors))
    head = out.read_text().splitlines()[0].split(",")
    assert [c for c in head if c in CHARACTERISTICS] == list(CHARACTERISTICS)
    from mhtrack.io import read_plots

    plots = read_plots(out, read_sensors(sensors))
    rec = read_recording(path)
    order = np.argsort(plots.file_row)
    np.testing.assert_array_equal(plots.attrs.amplitude[order], rec.plots["amplitude"])
    from mhtrack.sources import open_source

    src = open_source(path, sensors=read_sensors(sensors))
    rows, amps = [], []
    for scan in src:
        rows.append(src.file_rows(scan.rows))
        amps.append(np.asarray(scan.attrs.amplitude))
    got = np.concatenate(amps)[np.argsort(np.concatenate(rows))]
    np.testing.assert_array_equal(got, rec.plots["amplitude"])


def test_without_130_no_columns(tmp_path):
    path, _ = _file(tmp_path, n=20, with_130=False)
    rec = read_recording(path)
    assert not set(CHARACTERISTICS) & set(rec.plots) and "amplitude" not in rec.plots


def test_cat001_received_power_is_the_amplitude():
    """A CAT001 plot record by hand (FSPEC 0xE3 0x20: I001/010, 020, 040, 141, then 131;
    020 SSRPSR 2 = secondary, 131 = 0xC8 = −56 dBm in two's complement, 1 dBm): its
    amplitude is that received power, the other characteristics absent (pyasteryx has no
    CAT001 specification: the value is checked by hand)."""
    from mhtrack.io.asterix.decode import PLOT_COLUMNS, Decoder, plot_columns
    from mhtrack.io.asterix.problems import Problems

    rec = bytes([0xE3, 0x20, 25, 12, 0b0010_0000]) + (50 * 128).to_bytes(2, "big") + \
        (1 << 14).to_bytes(2, "big") + (200 * 128).to_bytes(2, "big") + bytes([0xC8])
    block = bytes([1]) + (3 + len(rec)).to_bytes(2, "big") + rec
    found = [r for _, kind, rows in Decoder().blocks(block, 0, Problems(), when=36000.0)
             for r in rows if kind == "plots"]
    p = plot_columns(found)
    assert len(found) == 1 and len(found[0]) == len(PLOT_COLUMNS) + len(CHARACTERISTICS)
    assert p["amplitude"].tolist() == [-56.0]
    assert all(np.isnan(p[c][0]) for c in CHARACTERISTICS[:-1])
