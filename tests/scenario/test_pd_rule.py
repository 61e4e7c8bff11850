"""One rule for a sensor's detection probability: P_D in (0, 1], in the Python API
(overrides, scenario dicts), scenario TOML files and the CLI's --pd."""

import pytest
from click.testing import CliRunner

from mhtrack.cli.main import cli
from mhtrack.scenario import from_dict, load_scenario, preset


@pytest.mark.parametrize("pd", [0.0, -0.1, 1.5])
def test_overrides_refuse_pd_outside_0_1(pd):
    with pytest.raises(ValueError, match=r"pd: must be in \(0, 1\]"):
        preset("crossing", pd=pd)


def test_pd_one_is_allowed():
    assert preset("crossing", pd=1.0).pd[0] == 1.0


def test_scenario_dict_and_toml_refuse_pd_zero(tmp_path):
    d = preset("crossing").to_dict()
    d["sensors"][0]["pd"] = 0.0
    with pytest.raises(ValueError, match=r"sensors\[0\]\.pd: must be in \(0, 1\]"):
        from_dict(d)
    from mhtrack.io import write_scenario_toml

    d["sensors"][0]["pd"] = 0.5
    path = tmp_path / "s.toml"
    write_scenario_toml(d, path)
    text = path.read_text()
    assert "pd = 0.5" in text
    path.write_text(text.replace("pd = 0.5", "pd = 0.0"))
    with pytest.raises(ValueError, match=r"s\.toml.*pd: must be in \(0, 1\]"):
        load_scenario(path)


@pytest.mark.parametrize("args", [["--pd", "0"], ["--tracker-pd", "0"]])
def test_cli_refuses_pd_zero_before_any_work(tmp_path, args):
    out = tmp_path / "r"
    r = CliRunner().invoke(cli, ["run", "crossing", "--scans", "3", "--out", str(out), *args])
    assert r.exit_code == 2
    assert args[0] in r.stderr and "Traceback" not in r.stderr
    assert not out.exists()
