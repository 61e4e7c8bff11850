"""``cluster`` and ``initiate`` through click's runner (the commands are registered in
``cli/main.py`` by the lead; here they are invoked directly)."""

import json

import pytest
from click.testing import CliRunner

from mhtrack.cli.initiation_commands import COMMANDS, cluster, initiate

TIMES = ("t_scan", "t_window", "t_fusion_scan")


def run(cmd, *args):
    r = CliRunner().invoke(cmd, [*args, "--no-progress"])
    assert r.exit_code == 0, r.output
    return r.output


def test_commands_exported():
    assert {c.name for c in COMMANDS} == {"cluster", "initiate"}


def test_cluster_json_and_determinism():
    args = ("multiradar", "--clutter-rate", "0", "--runs", "3", "--scans", "4", "--seed", "7",
            "--json")
    a = json.loads(run(cluster, *args))
    b = json.loads(run(cluster, *args))
    assert a["k_correct_rate"] == 1.0 and a["n_scans"] == 12
    assert a["fused_error_mean"] < 60.0  # fused plots near the truth (σ of a plot ≈ 50 m)
    for d in (a, b):
        for k in TIMES:
            d.pop(k, None)
    assert a == b
    r = json.loads(run(cluster, *args[:-3], "--method", "random", "--json"))
    assert r["method"] == "random" and 0.0 <= r["k_correct_rate"] <= 1.0


@pytest.mark.parametrize("method", ["logic", "modified-logic", "hough", "modified-hough"])
def test_initiate_json(method):
    out = json.loads(run(initiate, "multiradar", "--method", method, "--runs", "2",
                         "--scans", "5", "--clutter-rate", "5", "--json"))
    assert out["n_windows"] == 4 and out["n_runs"] == 2
    assert 0.0 <= out["p_true"] <= 1.0
    for k in ("p_false", "false_per_run", "t_window", "t_fusion_scan"):
        assert k in out


def test_initiate_same_seed_same_output_and_text(tmp_path):
    args = ("multiradar", "--runs", "2", "--scans", "5", "--seed", "3", "--json")
    a, b = (json.loads(run(initiate, *args)) for _ in range(2))
    for d in (a, b):
        for k in TIMES:
            d.pop(k, None)
    assert a == b
    text = run(initiate, *args[:-1], "--fusion", "none", "--figure", str(tmp_path / "f.png"))
    assert "p_true" in text and (tmp_path / "f.png").stat().st_size > 0
    # --out (-o) is the name now; --figure, the former one, is a hidden alias
    run(initiate, *args[:-1], "--fusion", "none", "-o", str(tmp_path / "g.png"))
    assert (tmp_path / "g.png").stat().st_size > 0
    assert "--figure" not in CliRunner().invoke(initiate, ["--help"]).output


def test_initiate_needs_a_four_scan_window():
    r = CliRunner().invoke(initiate, ["multiradar", "--scans", "3"])
    assert r.exit_code == 2 and "4-scan windows" in r.output


def test_initiate_rejects_bad_velocity_gate():
    r = CliRunner().invoke(initiate, ["multiradar", "--v-min", "500", "--v-max", "400"])
    assert r.exit_code != 0
