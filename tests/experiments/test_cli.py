"""``mhtrack montecarlo`` through click's runner."""

import json

import pytest
from click.testing import CliRunner

from mhtrack.cli.experiment_commands import COMMANDS, montecarlo

SMALL = ["crossing", "--clutter", "uniform", "--clutter-rate", "5", "--scans", "12",
         "--runs", "2", "--seed", "4", "--no-progress"]


def invoke(*args: str) -> tuple[int, str, str]:
    r = CliRunner().invoke(montecarlo, list(args))
    return r.exit_code, r.stdout, r.stderr


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("mc-cli")
    code, stdout, stderr = invoke(*SMALL, "--trackers", "mht,mht-agmm", "--workers", "1",
                                  "--out", str(out), "--json")
    assert code == 0, stderr
    return out, json.loads(stdout)


def test_commands_exported():
    assert [montecarlo] == COMMANDS


def test_json_output_keys(study):
    out, obj = study
    assert list(obj) == ["mht", "mht-agmm"]
    for entry in obj.values():
        for k in ("ospa_mean", "gospa_mean", "mota", "motp", "cardinality_error_mean",
                  "t_avg"):
            assert isinstance(entry[k], float)
            assert k in entry["std"]
        assert entry["n_runs"] == 2 and entry["failed"] == []
        ps = entry["per_scan"]
        assert {"scans", "ospa", "ospa_std", "cardinality", "cardinality_std",
                "cardinality_true"} <= set(ps)
        assert len(ps["ospa"]) == len(ps["scans"]) == 12
    for name in ("montecarlo.json", "summary.md", "ospa_cardinality.png"):
        assert (out / name).is_file()
    assert sorted(p.name for p in (out / "runs" / "mht").iterdir()) == [
        "run-0.parquet", "run-1.parquet"]
    spec = json.loads((out / "montecarlo.json").read_text())
    assert spec["run_kwargs"] == {"cutoff": 500.0, "order": 2.0, "output": "history"}


def test_rerun_resumes_and_prints_the_table(study):
    out, _ = study
    code, stdout, stderr = invoke(*SMALL, "--trackers", "mht,mht-agmm", "--workers", "1",
                                  "--out", str(out))
    assert code == 0, stderr
    assert "| ospa_mean |" in stdout and "0 runs computed, 4 already done" in stdout


def test_other_parameters_are_refused(study):
    out, _ = study
    code, _, stderr = invoke(*SMALL, "--trackers", "mht", "--workers", "1", "--nscan", "2",
                             "--out", str(out))
    assert code == 2
    assert "other parameters" in stderr and "config" in stderr


def test_failed_runs_exit_non_zero(tmp_path):
    code, stdout, stderr = invoke(*SMALL, "--trackers", "mht", "--runs", "1", "--workers",
                                  "1", "--run-kwarg", "fusion=bogus", "--out",
                                  str(tmp_path), "--json")
    assert code == 1
    assert "1 run(s) failed" in stderr
    assert json.loads(stdout)["mht"]["failed"] == [0]
    assert "unknown fusion 'bogus'" in (tmp_path / "runs" / "mht" / "run-0.error.txt").read_text()


def test_bad_options(tmp_path):
    code, _, stderr = invoke(*SMALL, "--trackers", "mht,bogus", "--out", str(tmp_path))
    assert code == 2 and "bogus" in stderr
    code, _, stderr = invoke(*SMALL, "--workers", "2", "--dask-scheduler", "tcp://x:1",
                             "--out", str(tmp_path))
    assert code == 2 and "not both" in stderr
