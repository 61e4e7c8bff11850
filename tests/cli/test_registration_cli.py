"""``simulate --bias`` and ``track --estimate-bias`` end to end (click's runner): 300 s of
opensky-radars with the issue's biases; the estimates against the true biases, the state
file read back by a second run."""

from __future__ import annotations

import json

from click.testing import CliRunner

from mhtrack.cli.main import cli


def invoke(*args: str) -> tuple[int, str, str]:
    r = CliRunner().invoke(cli, [str(a) for a in args])
    return r.exit_code, r.stdout, r.stderr


def test_estimate_bias_recovers_the_simulated_biases(tmp_path) -> None:
    d = tmp_path / "sim"
    code, _, err = invoke("simulate", "opensky-radars", "--seed", "1", "--scans", "30",
                          "--out", d, "--bias", "1:range=200,azimuth=-0.12",
                          "--bias", "2:gain=1.002,azimuth=0.08")
    assert code == 0, err
    assert "range_bias = 200.0" in (d / "scenario.toml").read_text()
    assert "bias" not in (d / "sensors.toml").read_text()  # the tracker is not told
    code, out, err = invoke("track", d / "plots.csv", "--sensors", d / "sensors.toml",
                            "--out", tmp_path / "t.csv", "--estimate-bias",
                            "--bias-reference", "3", "--bias-out", tmp_path / "b.json")
    assert code == 0, err
    assert "registration bias (reference sensors: 3;" in out
    b = json.loads((tmp_path / "b.json").read_text())["radars"]
    for sid, key, true in (("1", "range_offset", 200.0), ("1", "azimuth_deg", -0.12),
                           ("2", "range_gain", 1.002), ("2", "azimuth_deg", 0.08)):
        v = b[sid][key]
        assert abs(v - true) <= 0.2 * abs(true if key != "range_gain" else true - 1), (sid,
                                                                                      key, v)
    # a later run starts from the state: its prior σ are the first run's
    code, _, err = invoke("track", d / "plots.csv", "--sensors", d / "sensors.toml",
                             "--out", tmp_path / "t2.csv", "--estimate-bias",
                             "--bias-reference", "3", "--bias-init", tmp_path / "b.json",
                             "--bias-out", tmp_path / "b2.json")
    assert code == 0, err
    b2 = json.loads((tmp_path / "b2.json").read_text())["radars"]
    assert b2["1"]["sigma_range_offset"] < b["1"]["sigma_range_offset"]


def test_bias_options_need_estimate_bias(tmp_path) -> None:
    d = tmp_path / "sim"
    assert invoke("simulate", "opensky-radars", "--seed", "1", "--scans", "2", "--out",
                  d)[0] == 0
    code, _, err = invoke("track", d / "plots.csv", "--sensors", d / "sensors.toml",
                          "--out", tmp_path / "t.csv", "--bias-out", tmp_path / "b.json")
    assert code != 0 and "--estimate-bias" in err
    code, _, err = invoke("simulate", "opensky-radars", "--scans", "2", "--out",
                          tmp_path / "x", "--bias", "7:range=1")
    assert code != 0 and "sensor 7" in err


def test_run_simulates_biases_and_estimates_them(tmp_path) -> None:
    """``run --bias … --estimate-bias`` as ``simulate --bias`` then ``track
    --estimate-bias``: the same estimates written by --bias-out, to a tenth of their σ
    (``track`` reads the plots back from CSV, ``run`` tracks them in memory)."""
    bias = ("--bias", "1:range=200,azimuth=-0.12")
    est = ("--estimate-bias", "--bias-reference", "3")
    code, _, err = invoke("run", "opensky-radars", "--seed", "1", "--scans", "20",
                          *bias, *est, "--bias-out", tmp_path / "run.json",
                          "--out", tmp_path / "r", "--json")
    assert code == 0, err
    assert "registration bias (reference sensors: 3;" in err
    d = tmp_path / "sim"
    assert invoke("simulate", "opensky-radars", "--seed", "1", "--scans", "20", "--out",
                  d, *bias)[0] == 0
    code, _, err = invoke("track", d / "plots.csv", "--sensors", d / "sensors.toml",
                          "--out", tmp_path / "t.csv", *est, "--bias-out",
                          tmp_path / "track.json")
    assert code == 0, err
    by_run = json.loads((tmp_path / "run.json").read_text())["radars"]
    by_track = json.loads((tmp_path / "track.json").read_text())["radars"]
    assert by_run.keys() == by_track.keys() == {"1", "2"}
    for sid, est in by_run.items():
        for key in ("range_offset", "range_gain", "azimuth_deg"):
            assert abs(est[key] - by_track[sid][key]) < 0.1 * est[f"sigma_{key}"], (sid, key)
    assert abs(by_run["1"]["range_offset"] - 200.0) < 40.0


def test_run_and_live_bias_options_need_estimate_bias(tmp_path) -> None:
    code, _, err = invoke("run", "opensky-radars", "--scans", "2", "--out", tmp_path / "r",
                          "--bias-out", tmp_path / "b.json")
    assert code != 0 and "--estimate-bias" in err
    sensors = tmp_path / "s.toml"
    sensors.write_text('[[sensors]]\nid = 1\nkind = "polar"\npd = 0.9\nlat = 52.0\n'
                       'lon = 0.0\nsigma_range = 30.0\nsigma_bearing_deg = 0.1\nperiod = 4.0\n')
    code, _, err = invoke("live", "--stdin", "raw", "--sensors", sensors, "--bias-reference",
                          "1")
    assert code != 0 and "--estimate-bias" in err
