"""Real feeds through the recording source: every datagram received twice (redundant LANs)
gives the frames of the single copy; every framing gives the frames of the plain pcap;
reports that are no plots are left out and counted (issue 28)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from mhtrack.io.asterix import export, wrap
from mhtrack.io.asterix.container import blocks as split_blocks
from mhtrack.io.asterix.framings import units
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.sensors import read_sensors
from mhtrack.models.radars import SensorSet
from mhtrack.sources import open_source

from .conftest import differences


@pytest.fixture(scope="module")
def rec(opensky2: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("feeds") / "rec.pcap"
    export(opensky2 / "plots.csv", read_sensors(opensky2 / "sensors.toml"), path)
    return path


def _blocks_and_times(path: Path) -> tuple[list[bytes], list[float]]:
    """Every data block of a pcap and its packet's capture time."""
    out, times = [], []
    for offset, when, payload in units(path.read_bytes(), "pcap", "x", {34, 48},
                                       Problems()):
        for at, _, raw in split_blocks(payload, offset, Problems()):
            start = at - offset
            out.append(bytes(payload[start:start + 3 + len(raw)]))
            times.append(float(when))  # type: ignore[arg-type]
    return out, times


def _frames(path: Path, sensors: Path | SensorSet | None):  # type: ignore[no-untyped-def]
    s = read_sensors(sensors) if isinstance(sensors, Path) else sensors
    src = open_source(path, sensors=s)
    return list(src), src


def test_every_datagram_doubled_gives_the_single_copy(rec: Path, opensky2: Path,
                                                      tmp_path: Path) -> None:
    blocks, times = _blocks_and_times(rec)
    eth = wrap.udp_frames(blocks, 513)
    frames, ftimes = [], []
    for f, t in zip(eth, times, strict=True):  # LAN B: another source MAC, 0.7 ms later
        frames += [f, f[:6] + bytes([2, 0, 0, 0, 0, 9]) + f[12:]]
        ftimes += [t, t + 0.0007]
    (tmp_path / "two_lans.pcap").write_bytes(wrap.pcap(frames, ftimes))
    (tmp_path / "twice.ast").write_bytes(b"".join(b + b for b in blocks))  # no times
    ref, src0 = _frames(rec, opensky2 / "sensors.toml")
    assert not src0.stats.skipped and len(ref) > 300
    for name in ("two_lans.pcap", "twice.ast"):
        got, src = _frames(tmp_path / name, opensky2 / "sensors.toml")
        assert differences(ref, got) == [], name
        assert src.stats.skipped == {"duplicate": len(blocks)}, name
        rows = np.concatenate([f.rows for f in got])
        assert np.array_equal(src.file_rows(rows), src0.file_rows(rows)), name


def test_every_framing_gives_the_frames_of_the_plain_pcap(rec: Path, opensky2: Path,
                                                          tmp_path: Path) -> None:
    blocks, times = _blocks_and_times(rec)
    eth = wrap.udp_frames(blocks, 513)
    files = {
        "a.pcapng": wrap.pcapng(eth, times, tsresol=9),
        "be.pcap": wrap.pcap(eth, times, order=">", nano=True),
        "vlan.pcap": wrap.pcap([wrap.vlan(f, [(0x88A8, 3), (0x8100, 5)]) for f in eth],
                               times),
        "sll.pcap": wrap.pcap([wrap.sll(f) for f in eth], times, link=113),
        "sll2.pcapng": wrap.pcapng([wrap.sll2(f) for f in eth], times, link=276),
        "llc.pcap": wrap.pcap([wrap.llc_frame(b, 513) for b in blocks], times),
        "oradis_udp.pcap": wrap.pcap(wrap.udp_frames(
            [wrap.oradis([b], [t]) for b, t in zip(blocks, times, strict=True)], 513), times),
        "rec.gps": wrap.gps(blocks, times, b"GPS recorder"),
        "rec.ff": wrap.final(blocks, times),
        "rec.oradis": wrap.oradis(blocks, times),
        "rec.ast": b"".join(blocks),
    }
    ref, _ = _frames(rec, opensky2 / "sensors.toml")
    kinds = {}
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
        got, src = _frames(tmp_path / name, opensky2 / "sensors.toml")
        kinds[name] = src.container
        assert differences(ref, got) == [], name
        assert not src.stats.skipped, (name, src.stats.skipped)
    assert set(kinds.values()) == {"pcap", "pcapng", "gps", "final", "oradis", "raw"}


def test_reports_that_are_no_plots_are_left_out(opensky2: Path, tmp_path: Path) -> None:
    """Radar-extrapolated reports (I048/020 TYP 0, no detection) among the plots: the
    frames are those of the recording without them; the count is kept."""
    import pyarrow.csv as pacsv

    sensors = read_sensors(opensky2 / "sensors.toml")
    t = pacsv.read_csv(opensky2 / "plots.csv")
    n = t.num_rows
    typ = np.where(np.arange(n) % 7 == 3, 0, 2)  # every 7th report: no detection
    pacsv.write_csv(t.append_column("typ", [typ]), tmp_path / "mixed.csv")
    pacsv.write_csv(t.filter(typ != 0).append_column("typ", [typ[typ != 0]]),
                    tmp_path / "plots.csv")
    for name in ("mixed", "plots"):
        export(tmp_path / f"{name}.csv", sensors, tmp_path / f"{name}.pcap")
    ref, _ = _frames(tmp_path / "plots.pcap", sensors)
    got, src = _frames(tmp_path / "mixed.pcap", sensors)
    assert src.stats.skipped == {"not_plot": int((typ == 0).sum())}
    assert [f.z.tolist() for f in got] == [f.z.tolist() for f in ref]
    assert [f.t.tolist() for f in got] == [f.t.tolist() for f in ref]


def test_cat001_plots_give_the_frames_of_their_cat048_twins(rec: Path, opensky2: Path,
                                                           tmp_path: Path) -> None:
    """The recording's plots re-encoded as CAT001 (time truncated to 512 s, restored from
    the CAT002 north markers) with CAT002 marks: the same frames and times (both 1/128 s),
    positions within one CAT001 range LSB (1/128 NM; bearings share their LSB)."""
    from mhtrack.io.asterix import encode_other, read_recording

    r = read_recording(rec)
    p, w = r.plots, r.sweeps
    msgs = [(t, s, 1, encode_other.plot001(t, s, rho, th, typ=2))
            for t, s, rho, th in zip(p["time"].tolist(), p["sensor"].tolist(),
                                     p["slant_range"].tolist(), p["bearing"].tolist(),
                                     strict=True)]
    msgs += [(t, s, 2, encode_other.mark002(t, s, k, 0.0 if np.isnan(a) else a))
             for t, s, k, a in zip(w["time"].tolist(), w["sensor"].tolist(),
                                   w["kind"].tolist(), w["azimuth"].tolist(), strict=True)]
    got_blocks = encode_other.blocks(msgs)
    data = wrap.pcap(wrap.udp_frames([b for _, _, b in got_blocks], 513),
                     [t for t, _, _ in got_blocks])
    (tmp_path / "cat001.pcap").write_bytes(data)
    sensors = read_sensors(opensky2 / "sensors.toml")
    ref, _ = _frames(rec, sensors)
    got, src = _frames(tmp_path / "cat001.pcap", sensors)
    assert not src.stats.skipped
    assert len(got) == len(ref) > 300
    for a, b in zip(ref, got, strict=True):
        assert np.array_equal(a.t, b.t) and np.array_equal(a.sensor, b.sensor)
        assert np.abs(a.z - b.z).max() <= 1852.0 / 128


def test_adsb_reports_are_a_sensor_of_their_own(rec: Path, opensky2: Path,
                                                tmp_path: Path) -> None:
    """CAT021 reports beside the radars' CAT048: a station the sensors file does not list
    becomes a sensor of kind ``adsb``; each report at its WGS-84 position in the local
    frame, σ from its NACp (DO-260B EPU as a 95 % radius); NACp 0 counted and left out."""
    from mhtrack.io.asterix import encode_other
    from mhtrack.io.asterix.cat021 import NACP_EPU_M, R95_TO_SIGMA

    sensors = read_sensors(opensky2 / "sensors.toml")
    blocks, times = _blocks_and_times(rec)
    rng = np.random.default_rng(3)
    n, station = 30, 7 * 256 + 9
    t = np.sort(rng.uniform(times[0], times[-1], n)) % 86400.0
    lat, lon = rng.uniform(50, 52, n), rng.uniform(3, 6, n)
    nacp = np.where(np.arange(n) % 10 == 4, 0, rng.integers(7, 12, n))
    msgs = [(ti, station, 21, encode_other.report021(ti, station, la, lo, nacp=int(k)))
            for ti, la, lo, k in zip(t.tolist(), lat.tolist(), lon.tolist(), nacp.tolist(),
                                     strict=True)]
    adsb = [b for m in msgs for b in encode_other.blocks([m])]  # a block per report
    pairs = sorted([(tb, b) for tb, b in zip(times, blocks, strict=True)]
                   + [(tb + times[0] - times[0] % 86400.0, b) for tb, _, b in adsb],
                   key=lambda x: x[0])
    data = wrap.pcap(wrap.udp_frames([b for _, b in pairs], 513), [x for x, _ in pairs])
    (tmp_path / "mixed.pcap").write_bytes(data)
    ref, _ = _frames(rec, sensors)
    got, src = _frames(tmp_path / "mixed.pcap", sensors)
    assert src.sensors.sensor(station).kind == "adsb"
    assert src.stats.skipped == {"no_accuracy": int((nacp == 0).sum())}
    radar = [f for f in got if f.sensor[0] != station]  # the radars' frames unchanged
    assert len(radar) == len(ref) and all(
        np.array_equal(a.z, b.z) and np.array_equal(a.t, b.t) and np.array_equal(a.R, b.R)
        for a, b in zip(ref, radar, strict=True))
    mine = [f for f in got if f.sensor[0] == station]
    z = np.concatenate([f.z for f in mine])
    R = np.concatenate([f.R for f in mine])
    keep = nacp > 0
    x, y = sensors.frame().to_local(lat[keep], lon[keep])
    order = np.argsort(np.concatenate([f.t for f in mine]), kind="stable")
    assert np.abs(z[order] - np.column_stack((x, y))).max() < 0.1  # 180/2^30 deg LSB
    sigma = np.array([NACP_EPU_M[int(k)] for k in nacp[keep]]) * R95_TO_SIGMA
    assert np.allclose(R[order][:, 0, 0], sigma**2) and np.all(R[:, 0, 1] == 0)


@pytest.mark.parametrize("ars", ["absent", "zero"])
def test_period_from_north_markers_without_i034_041(opensky2: Path, tmp_path: Path,
                                                    ars: str) -> None:
    """CAT034 without I034/041, or with a period of 0: the period is the north markers'
    interval, never a refusal of a sensors file that has no period."""
    import pyarrow.csv as pacsv

    from mhtrack.io.asterix.encode import encode_blocks, plot_messages, sweep_messages

    sensors = read_sensors(opensky2 / "sensors.toml")
    tab = pacsv.read_csv(opensky2 / "plots.csv")
    t, s, b, r = (tab.column(k).to_numpy() for k in ("time", "sensor", "bearing", "range"))
    periods = {x.id: float(x.period) for x in sensors.sensors}
    msgs = plot_messages(t, s, r, b, {})  # ground range as slant range: fine here
    marks = sweep_messages(t, s, b, periods)
    for m in marks:
        if "041" in m.items:
            if ars == "absent":
                del m.items["041"]
            else:
                m.items["041"] = 0
    (tmp_path / "rec.ast").write_bytes(b"".join(x for _, _, x in
                                               encode_blocks(msgs + marks)))
    bare = replace(sensors, sensors=tuple(replace(x, period=None) for x in sensors.sensors))
    src = open_source(tmp_path / "rec.ast", sensors=bare)
    assert len(list(src)) > 300
    for x in src.sensors.sensors:  # north markers a period apart, each on a 1/128 s LSB
        assert x.period == pytest.approx(periods[x.id], abs=1 / 128)


def test_frames_cut_at_the_radars_own_sectors(rec: Path, opensky2: Path) -> None:
    """``sectors=True``: no frame of a radar spans one of its sector crossings or north
    markers (a plot at the crossing's time, to the 1/128 s LSB, may be either side: its
    arrival order decides), none is longer than today's rule allows, and the plots are
    those of today's frames."""
    from mhtrack.frames import frame_lengths
    from mhtrack.io.asterix import read_recording
    from mhtrack.sources.recording import AsterixSource

    sensors = read_sensors(opensky2 / "sensors.toml")
    ref, _ = _frames(rec, sensors)
    src = AsterixSource(rec, sensors=sensors, sectors=True)
    got = list(src)
    sweeps = read_recording(rec).sweeps
    length = frame_lengths({s.id: s.period for s in sensors.sensors})
    crossings = 0
    for f in got:
        s = int(f.sensor[0])
        marks = sweeps["time"][sweeps["sensor"] == s]
        inside = (marks > f.t.min()) & (marks < f.t.max())
        assert not inside.any(), (f.index, s)
        assert f.t.max() - f.t.min() <= length[s]
        crossings += int(((marks > f.t.min() - length[s]) & (marks <= f.t.min())).any())
    assert crossings > len(got) // 2  # most frames open just after a crossing
    assert len(got) > len(ref)  # cut at crossings as well as by length
    z = lambda fs: np.concatenate([f.z for f in fs])  # noqa: E731
    t = lambda fs: np.concatenate([f.t for f in fs])  # noqa: E731
    assert np.array_equal(np.sort(t(got)), np.sort(t(ref)))
    assert np.array_equal(np.sort(z(got), axis=0), np.sort(z(ref), axis=0))
