"""``simulate``, ``evaluate`` and ``plot`` end to end through the CLI (click's runner)."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli


def invoke(*args: str) -> tuple[int, str, str]:
    r = CliRunner().invoke(cli, list(args))
    return r.exit_code, r.stdout, r.stderr


@pytest.fixture(scope="module")
def crossing(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("c1")
    code, _stdout, stderr = invoke("simulate", "crossing", "--seed", "1", "--out", str(out))
    assert code == 0, stderr
    return out


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as f:
        return list(csv.DictReader(f))


def test_simulate_crossing_counts(crossing):
    plots = _rows(crossing / "plots.csv")
    truth = _rows(crossing / "truth.csv")
    assert {r["scan"] for r in truth} == {str(k) for k in range(1, 91)}
    clutter = sum(r["origin"] == "-1" for r in plots)
    # Poisson(40) per scan over 90 scans: mean within 40 ± 4 sd of the mean
    assert abs(clutter / 90 - 40) < 4 * np.sqrt(40 / 90)
    detected = len(plots) - clutter
    n, p = len(truth), 0.9
    assert abs(detected - p * n) < 4 * np.sqrt(n * p * (1 - p))
    assert (crossing / "scenario.toml").is_file()


def test_simulate_writes_reloadable_scenario(crossing, tmp_path):
    code, _, stderr = invoke("simulate", str(crossing / "scenario.toml"), "--seed", "1",
                             "--out", str(tmp_path))
    assert code == 0, stderr
    assert (tmp_path / "plots.csv").read_bytes() == (crossing / "plots.csv").read_bytes()


def test_evaluate_truth_against_itself(crossing):
    t = str(crossing / "truth.csv")
    code, stdout, stderr = invoke("evaluate", t, t, "--json")
    assert code == 0, stderr
    d = json.loads(stdout)
    assert d["ospa_mean"] == 0 and d["mota"] == 1 and d["id_switches"] == 0
    for key in ("gospa_mean", "cardinality_error_mean", "motp", "fragmentations", "n_tracks",
                "ospa", "cardinality"):
        assert key in d
    assert len(d["ospa"]) == 90


def test_evaluate_one_target_removed_matches_hand_ospa(crossing, tmp_path):
    truth = _rows(crossing / "truth.csv")
    kept = [r for r in truth if r["target_id"] != "2"]
    tracks = tmp_path / "tracks.csv"
    with tracks.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scan", "time", "track_id", "x", "y", "vx", "vy", "plot"])
        for r in kept:
            w.writerow([r["scan"], r["time"], r["target_id"], r["x"], r["y"], r["vx"], r["vy"], ""])
    code, stdout, stderr = invoke("evaluate", str(tracks), str(crossing / "truth.csv"),
                                  "--json", "--cutoff", "500", "--order", "2")
    assert code == 0, stderr
    d = json.loads(stdout)
    # Hand computation: at a scan with m live targets, one of them (target 2) unmatched and
    # the others matched exactly, OSPA = (c^p (n - m... ) / m)^(1/p) = (500² / m)^(1/2);
    # scans where target 2 is not alive have OSPA 0.
    live: dict[str, set[str]] = {}
    for r in truth:
        live.setdefault(r["scan"], set()).add(r["target_id"])
    expected = [np.sqrt(500.0**2 / len(ids)) if "2" in ids else 0.0
                for _, ids in sorted(live.items(), key=lambda kv: int(kv[0]))]
    assert np.allclose(d["ospa"], expected)
    assert d["ospa_mean"] == pytest.approx(np.mean(expected))
    assert d["mota"] < 1


def test_plot_writes_png(crossing, tmp_path):
    out = tmp_path / "scene.png"
    code, _stdout, stderr = invoke("plot", str(crossing), "-o", str(out))
    assert code == 0, stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert out.stat().st_size > 10_000


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["simulate", "nowhere", "--out", "X"], "unknown scenario 'nowhere'"),
        (["simulate", "crossing", "--pd", "2", "--out", "X"], "--pd"),
        (["simulate", "missing.toml", "--out", "X"], "no such scenario file"),
        (["evaluate", "no.csv", "no2.csv"], "no.csv"),
        (["plot", "."], "holds no plots"),
    ],
)
def test_bad_input_is_one_clear_line(args, needle, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _stdout, stderr = invoke(*args)
    assert code != 0
    assert needle in stderr
    assert "Traceback" not in stderr


def test_malformed_plots_file_names_line_and_column(crossing, tmp_path):
    bad = tmp_path / "plots.csv"
    lines = (crossing / "plots.csv").read_text().splitlines()
    parts = lines[5].split(",")
    parts[3] = "nan"
    lines[5] = ",".join(parts)
    bad.write_text("\n".join(lines) + "\n")
    t = str(crossing / "truth.csv")
    code, _, stderr = invoke("evaluate", t, t, "--plots", str(bad))
    assert code != 0
    assert "plots.csv, line 6, column 'x'" in stderr
    assert "Traceback" not in stderr


def test_bad_scenario_toml_names_the_key(crossing, tmp_path):
    text = (crossing / "scenario.toml").read_text()
    assert "\nT = 1.0\n" in text
    src = tmp_path / "s.toml"
    src.write_text(text.replace("\nT = 1.0\n", "\nT = -1.0\n"))
    code, _, stderr = invoke("simulate", str(src), "--out", str(tmp_path / "o"))
    assert code != 0 and "Traceback" not in stderr
    assert "s.toml" in stderr and "T:" in stderr


def test_evaluate_refuses_tracks_and_truth_of_different_times(crossing, tmp_path):
    truth = crossing / "truth.csv"
    lines = truth.read_text().splitlines()
    rows = [lines[0]]
    for line in lines[1:]:
        f = line.split(",")
        rows.append(",".join([f[0], repr(float(f[1]) * 10), *f[2:]]))
    slow = tmp_path / "tracks.csv"
    slow.write_text("\n".join(rows) + "\n")
    code, _, stderr = invoke("evaluate", str(slow), str(truth))
    assert code != 0 and "Traceback" not in stderr
    first = lines[1].split(",")
    assert (f"{slow} and {truth} give scan {first[0]} different times "
            f"({float(first[1]) * 10!r} s and {float(first[1])!r} s)") in stderr
    code, _, stderr = invoke("evaluate", str(truth), str(truth), "--plots",
                             str(crossing / "plots.csv"))
    assert code == 0, stderr


def test_simulate_rotating_radars_writes_timed_plots_truth_and_sensors(tmp_path):
    from mhtrack.io.sensors import read_sensors
    from mhtrack.models.geodesy import LocalFrame
    from mhtrack.scenario import preset, simulate

    code, stdout, stderr = invoke("simulate", "opensky-radars", "--seed", "1", "--scans", "7",
                                  "--out", str(tmp_path))
    assert code == 0, stderr
    assert "3 rotating radars over 60 s" in stdout
    plots, truth = _rows(tmp_path / "plots.csv"), _rows(tmp_path / "truth.csv")
    assert list(plots[0])[:5] == ["time", "sensor", "range", "bearing", "origin"]
    assert {"time", "target_id", "lat", "lon", "vx", "vy", "x", "y"} <= set(truth[0])
    sim = simulate(preset("opensky-radars", scans=7), seed=1)
    assert len(plots) == len(sim.plots)
    # the file is in time order; read back with its sensors it is the simulated table
    from mhtrack.io import read_plots

    ss = read_sensors(tmp_path / "sensors.toml")
    back = read_plots(tmp_path / "plots.csv", sensors=ss)
    np.testing.assert_array_equal(np.sort([float(r["time"]) for r in plots]),
                                  np.sort(sim.plots.time))
    np.testing.assert_array_equal(back.range, sim.plots.range)
    np.testing.assert_array_equal(back.scan, sim.plots.scan)
    np.testing.assert_allclose(back.x, sim.plots.x, atol=1e-6)
    assert ss == sim.scenario.sensor_set()
    # lat/lon of the truth are its x, y on the ellipsoid; vx, vy east/north keep the speed
    frame = LocalFrame(*ss.origin)
    x, y = frame.to_local([float(r["lat"]) for r in truth], [float(r["lon"]) for r in truth])
    np.testing.assert_allclose(x, [float(r["x"]) for r in truth], atol=1e-3)
    np.testing.assert_allclose(y, [float(r["y"]) for r in truth], atol=1e-3)
    speed = np.hypot([float(r["vx"]) for r in truth], [float(r["vy"]) for r in truth])
    np.testing.assert_allclose(speed, np.hypot(sim.truth.vx, sim.truth.vy), rtol=1e-3)


def test_simulated_rotating_radars_carry_ssr_attributes_by_default(tmp_path):
    """Rotating radars (secondary radars): the plots carry the attributes unless
    ``--no-attributes``, and are then :func:`with_attributes` of the plain simulation
    (positions unchanged); without rotating radars there are none unless asked, and a
    reply probability without attributes is a usage error."""
    from mhtrack.io import read_plots
    from mhtrack.io.sensors import read_sensors
    from mhtrack.scenario import preset, simulate
    from mhtrack.scenario.identity import with_attributes

    for name, flag in (("on", ()), ("off", ("--no-attributes",))):
        code, stdout, stderr = invoke("simulate", "opensky-radars", "--seed", "3", "--scans",
                                      "3", "--out", str(tmp_path / name), *flag)
        assert code == 0, stderr
        assert ("SSR attributes" in stdout) == (name == "on")
    ss = read_sensors(tmp_path / "on" / "sensors.toml")
    on, off = (read_plots(tmp_path / n / "plots.csv", sensors=ss) for n in ("on", "off"))
    assert off.attrs is None and on.attrs is not None
    np.testing.assert_array_equal(on.range, off.range)
    np.testing.assert_array_equal(on.origin, off.origin)
    plain = simulate(preset("opensky-radars", scans=3), seed=3)
    want = with_attributes(plain).plots.attrs.columns()
    p = plain.plots  # the file's rows matched to the simulation's by time, sensor, range
    mine, theirs = (np.lexsort((t.range, t.sensor, t.time)) for t in (on, p))
    np.testing.assert_array_equal(on.time[mine], p.time[theirs])
    got = on.attrs.columns()
    for k in ("plot_type", "mode_3a", "address", "flight_level"):
        np.testing.assert_array_equal(got[k][mine], want[k][theirs], err_msg=k)
    assert (got["address"] >= 0).sum() > 0.5 * (on.origin >= 0).sum()

    code, _, stderr = invoke("simulate", "crossing", "--scans", "2", "--out",
                             str(tmp_path / "c"))
    assert code == 0, stderr
    assert _rows(tmp_path / "c" / "plots.csv")[0].keys() == {
        "scan", "time", "sensor", "x", "y", "origin"}
    code, _, stderr = invoke("simulate", "radars-clutter", "--scans", "2", "--garble", "0.1",
                             "--no-attributes", "--out", str(tmp_path / "r"))
    assert code == 2 and "--garble" in stderr and "--no-attributes" in stderr
