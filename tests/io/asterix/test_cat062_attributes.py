"""CAT062 items of the tracks' attributes (issue 29 item 5): a tracks file with attribute
columns exported, decoded back by pyasteryx (an independent decoder), every item equal to
the file within one LSB and absent where the file's cell is empty; a tracker run's
CAT062 sink the same bytes as the export of its tracks file."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.attributes import TrackAttributes, address_text, code_text
from mhtrack.io.asterix.cat062_export import export_tracks
from mhtrack.io.asterix.cat062_items import cartesian
from mhtrack.io.tracks import read_tracks, write_tracks
from mhtrack.models.geodesy import LocalFrame
from mhtrack.records import TrackTable

pyasteryx = pytest.importorskip("pyasteryx")

FRAME = LocalFrame(51.47, -0.45)


def _table(n=400):
    rng = np.random.default_rng(4)
    some = rng.random((12, n)) < 0.8  # each attribute known on 80 % of the rows
    major = rng.uniform(5, 3000, n)
    a = TrackAttributes(
        flight_level=np.where(some[0], rng.uniform(-10, 450, n), np.nan),
        rate_of_climb=np.where(some[1], rng.uniform(-6000, 6000, n), np.nan),
        mode_3a=np.where(some[2], rng.integers(0, 0o10000, n), -1),
        address=np.where(some[3], rng.integers(0, 1 << 24, n), -1),
        callsign=np.array([f"BAW{int(k)}" if s else "" for k, s in
                           zip(rng.integers(1, 99999, n), some[4], strict=True)], object),
        sigma_major=np.where(some[5], major, np.nan),
        sigma_minor=np.where(some[5], major * rng.uniform(0.05, 1, n), np.nan),
        sigma_orient=np.where(some[5], rng.uniform(0, 180, n), np.nan),
        sensors=np.full(n, "", object), sensor_ages=np.full(n, "", object),
        # ages up to 90 s: beyond I062/290's 63.75 s some are saturated
        age_psr=np.where(some[6], rng.uniform(0, 90, n), np.nan),
        age_ssr=np.where(some[7], rng.uniform(0, 90, n), np.nan),
        age_mds=np.where(some[8], rng.uniform(0, 30, n), np.nan),
        # the row's plot: a sensor (SAC·256 + SIC), its type, code and level as received
        meas_sensor=np.where(some[9], rng.integers(0, 1 << 16, n), -1),
        meas_type=np.where(some[9], rng.integers(0, 5, n), 0),
        meas_mode_3a=np.where(some[9] & some[10], rng.integers(0, 0o10000, n), -1),
        meas_mode_3a_vg=np.where(some[9], rng.integers(0, 4, n), 0),
        meas_flight_level=np.where(some[9] & some[11], rng.uniform(-10, 450, n), np.nan),
        meas_flight_level_vg=np.where(some[9], rng.integers(0, 4, n), 0),
        # its measured position: ranges beyond I062/340 POS's 256 NM are not written
        meas_range=np.where(some[9] & some[10], rng.uniform(0, 500e3, n), np.nan),
        meas_bearing=np.where(some[9] & some[10], rng.uniform(0, 360, n), np.nan),
        existence_probability=np.where(some[0], rng.random(n), np.nan))
    return TrackTable(scan=np.arange(n), time=1000.0 + np.arange(n) * 0.25,
                      track_id=rng.integers(0, 5000, n), x=rng.uniform(-2e5, 2e5, n),
                      y=rng.uniform(-2e5, 2e5, n), vx=rng.uniform(-250, 250, n),
                      vy=rng.uniform(-250, 250, n),
                      plot=np.where(rng.random(n) < 0.2, -1, np.arange(n)),
                      tentative=rng.random(n) < 0.1, attrs=a)


def _decoded(path):
    return [m.items for m in pyasteryx.Decoder().decode_file(str(path))]


def _compare(tracks: TrackTable, items: list[dict]) -> None:
    """Each record against its row of the tracks file (the same track number and time
    of day, in 1/128 s: records are written in time order; a track reported twice at one
    time, by two frames, may match either), within one LSB."""
    a = tracks.attrs
    sx, sy, cxy = cartesian(a)
    assert len(items) == len(tracks)
    rows: dict[tuple[int, int], list[int]] = {}
    for i, (t, s) in enumerate(zip(tracks.track_id.tolist(), tracks.time.tolist(),
                                   strict=True)):
        rows.setdefault((int(t), round(s * 128)), []).append(i)

    def wrong(m: dict, i: int) -> list[str]:
        bad = []
        if m["I062/080"]["CNF"] != int(tracks.tentative[i]):
            bad.append("080 CNF")
        if m.get("I062/060", {}).get("Mode3A") != (code_text(a.mode_3a[i]) or None):
            bad.append("060")
        fl, roc = a.flight_level[i], a.rate_of_climb[i]
        got = m.get("I062/136", {}).get("MFL")  # 1/4 FL; pyasteryx gives feet
        if (got is None) != np.isnan(fl) or (got is not None and abs(got / 100 - fl) > 0.25):
            bad.append("136")
        got = m.get("I062/220", {}).get("RoC")
        if (got is None) != np.isnan(roc) or (got is not None and abs(got - roc) > 6.25):
            bad.append("220")
        adr = m.get("I062/380", {})
        if adr.get("ADR", {}).get("ADR") != (address_text(a.address[i]) or None):
            bad.append("380 ADR")
        if adr.get("ID", {}).get("ACID") != (a.callsign[i] or None):
            bad.append("380 ID")
        tid = m.get("I062/245")  # target identification: STI 0 (downlinked), CHR
        if (tid is None) != (not a.callsign[i]) or (
                tid is not None and (tid["STI"], tid["TId"]) != (0, a.callsign[i])):
            bad.append("245")
        ages = m.get("I062/290", {})
        for k, v in (("PSR", a.age_psr[i]), ("SSR", a.age_ssr[i]), ("MDS", a.age_mds[i])):
            got = ages.get(k, {}).get(k)
            if (got is None) != np.isnan(v) or (
                    got is not None and abs(got - min(v, 63.75)) > 0.25):
                bad.append(f"290 {k}")
        bad += _wrong_340(m.get("I062/340"), a, i)
        acc = m.get("I062/500")
        if (acc is None) != np.isnan(a.sigma_major[i]):
            bad.append("500 present")
        elif acc is not None:
            cov = np.sign(cxy[i]) * np.sqrt(abs(cxy[i]))
            if abs(acc["APC"]["APC_X"] - sx[i]) > 0.5 or \
                    abs(acc["APC"]["APC_Y"] - sy[i]) > 0.5 or \
                    abs(acc["COV"]["COV_XY"] - cov) > 0.5:
                bad.append("500")
        return bad

    for m in items:
        found = rows[(m["I062/040"]["TrkN"], round(m["I062/070"]["ToT"] * 128))]
        problems = [wrong(m, i) for i in found]
        assert any(not p for p in problems), (m, problems)


def _wrong_340(got: dict | None, a: TrackAttributes, i: int) -> list[str]:
    """I062/340 against the row's plot: SID = SAC·256 + SIC, TYP (1 PSR, 2 SSR, 3 both,
    5 Mode S), MDA code with V, G, MDC level within ¼ FL with V, G, POS range within
    1/256 NM and bearing within 360°/2¹⁶ (modulo 360°; absent beyond 256 NM)."""
    if (got is None) != (a.meas_sensor[i] < 0):
        return ["340 present"]
    if got is None:
        return []
    bad = []
    sid = got["SID"]["SAC"] * 256 + got["SID"]["SIC"]
    if sid != a.meas_sensor[i]:
        bad.append("340 SID")
    typ = {1: 1, 2: 2, 3: 3, 4: 5}.get(int(a.meas_type[i]))
    if got.get("TYP", {}).get("TYP") != typ:
        bad.append("340 TYP")
    mda, code = got.get("MDA"), a.meas_mode_3a[i]
    vg = int(a.meas_mode_3a_vg[i])
    if (mda is None) != (code < 0) or (mda is not None and (
            mda["Mode3A"], mda["V"], mda["G"]) != (code_text(code), vg >> 1, vg & 1)):
        bad.append("340 MDA")
    pos, r, b = got.get("POS"), a.meas_range[i], a.meas_bearing[i]
    if (pos is None) != (np.isnan(r) or r / 1852.0 > 65535 / 256) or (pos is not None and (
            abs(pos["RHO"] * 1852.0 - r) > 1852.0 / 256
            or abs((pos["THETA"] - b + 180.0) % 360.0 - 180.0) > 360.0 / 65536)):
        bad.append("340 POS")
    mdc, fl = got.get("MDC"), a.meas_flight_level[i]
    vg = int(a.meas_flight_level_vg[i])
    if (mdc is None) != np.isnan(fl) or (mdc is not None and (
            abs(mdc["ModeC"] - fl) > 0.25 or (mdc["CV"], mdc["CG"]) != (vg >> 1, vg & 1))):
        bad.append("340 MDC")
    return bad


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_items_decoded_by_pyasteryx_equal_the_tracks_file(tmp_path, suffix):
    write_tracks(_table(), tmp_path / f"t{suffix}", FRAME)
    back = read_tracks(tmp_path / f"t{suffix}")
    n, _ = export_tracks(tmp_path / f"t{suffix}", None, tmp_path / "t.ast")
    assert n == len(back) == 400
    _compare(back, _decoded(tmp_path / "t.ast"))


def test_a_file_without_attributes_exports_none(tmp_path):
    t = _table()
    write_tracks(TrackTable(**{f: getattr(t, f) for f in ("scan", "time", "track_id", "x",
                                                            "y", "vx", "vy", "plot")}),
                 tmp_path / "t.csv", FRAME)
    export_tracks(tmp_path / "t.csv", None, tmp_path / "t.ast")
    new = {"I062/060", "I062/136", "I062/220", "I062/380", "I062/500", "I062/245",
           "I062/290", "I062/340"}
    assert not any(new & set(m) for m in _decoded(tmp_path / "t.ast"))


def test_a_callsign_outside_the_icao_set_is_named(tmp_path):
    t = _table(8)
    t.attrs.callsign[3] = "baw_12"
    write_tracks(t, tmp_path / "t.csv", FRAME)
    with pytest.raises(Exception, match=r"line 5.*callsign.*BAW_12"):
        export_tracks(tmp_path / "t.csv", None, tmp_path / "t.ast")


def test_a_tracker_run_exports_its_attributes(tmp_path):
    """opensky-radars with attributes through the pipeline: the CAT062 sink's bytes are
    the export of the tracks file, whose every item pyasteryx decodes back."""
    from mhtrack.io import write_plots
    from mhtrack.io.sensors import write_sensors
    from mhtrack.pipeline import Pipeline, TrackOptions
    from mhtrack.scenario import preset, simulate
    from mhtrack.scenario.identity import AttributeOptions, add_attributes, opensky_identities
    from mhtrack.scenario.overrides import apply_overrides
    from mhtrack.sinks import Cat062Sink, TracksFileSink

    sc = apply_overrides(preset("opensky-radars"), scans=4)
    plots = add_attributes(simulate(sc, seed=2).plots, opensky_identities(),
                           AttributeOptions(), 2)
    write_plots(plots, tmp_path / "plots.csv")
    write_sensors(sc.sensor_set(), tmp_path / "sensors.toml")
    pipe = Pipeline.open(str(tmp_path / "plots.csv"), TrackOptions())
    pipe.run([TracksFileSink(tmp_path / "tracks.csv", frame=pipe.frame, output=pipe.output),
              Cat062Sink(tmp_path / "sink.ast", pipe.frame, output=pipe.output)])
    export_tracks(tmp_path / "tracks.csv", None, tmp_path / "export.ast")
    assert (tmp_path / "sink.ast").read_bytes() == (tmp_path / "export.ast").read_bytes()
    tracks = read_tracks(tmp_path / "tracks.csv")
    online = ~tracks.tentative
    # the tentative past carries the identity its branch had: the same address as the
    # confirmed track wherever it had one
    past = tracks.tentative & (tracks.attrs.address >= 0)
    assert past.sum() > 0.5 * tracks.tentative.sum()
    first = {int(t): int(a) for t, a in zip(tracks.track_id[online].tolist(),
                                             tracks.attrs.address[online].tolist(),
                                             strict=True)}
    same = [first.get(int(t), a) == a for t, a in zip(tracks.track_id[past].tolist(),
                                                       tracks.attrs.address[past].tolist(),
                                                       strict=True)]
    assert np.mean(same) > 0.99
    assert tracks.attrs is not None and (tracks.attrs.address[online] >= 0).mean() > 0.9
    known = np.isfinite(np.column_stack((tracks.attrs.age_psr, tracks.attrs.age_ssr,
                                         tracks.attrs.age_mds)))
    assert known[online].any(axis=1).mean() > 0.9  # the technologies' ages are filled
    upd = online & (tracks.plot >= 0)  # a row with a plot says what that plot measured
    assert (tracks.attrs.meas_sensor[upd] >= 0).all()
    assert (tracks.attrs.meas_sensor[tracks.plot < 0] < 0).all()
    # ... and where it was, as its radar measured it: the SLANT range of the plots file's
    # ground range (I062/340 POS RHO, as I048/040 of a recording) at the plot's flight
    # level, NaN without one; and the plots file's bearing
    from mhtrack.io.asterix.earth import slant_range

    measured = np.genfromtxt(tmp_path / "plots.csv", delimiter=",", names=True)
    k = tracks.plot[upd]
    ss = sc.sensor_set()
    sid = measured["sensor"][k].astype(int)
    lat = np.array([ss.site_latlon(int(i))[0] for i in sid])
    alt = np.array([ss.sensor(int(i)).alt or 0.0 for i in sid])
    fl = measured["flight_level"][k]
    want_rho = slant_range(measured["range"][k], measured["bearing"][k], fl * 30.48, lat,
                           alt)
    assert np.isfinite(fl).any() and np.isnan(fl).any()
    assert np.abs(want_rho - measured["range"][k])[np.isfinite(fl)].max() > 100.0
    np.testing.assert_allclose(tracks.attrs.meas_range[upd], want_rho, rtol=1e-12)
    np.testing.assert_allclose(tracks.attrs.meas_bearing[upd], measured["bearing"][k],
                               rtol=1e-12)
    assert np.isnan(tracks.attrs.meas_range[tracks.plot < 0]).all()
    _compare(tracks, _decoded(tmp_path / "export.ast"))
