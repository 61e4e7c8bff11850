"""The registration-bias state file (mhtrack.io.biasfile): round trip and bad input."""

from __future__ import annotations

import json

import pytest

from mhtrack.errors import InputError
from mhtrack.io.biasfile import read_biases, write_biases
from mhtrack.models.registration import RadarBias


def test_round_trip(tmp_path) -> None:
    b = {2: RadarBias(198.75, 1.00003, -0.1192, (2.0, 1e-5, 8e-4)), 1: RadarBias()}
    write_biases(tmp_path / "b.json", b, reference=[3])
    assert read_biases(tmp_path / "b.json") == b
    assert json.loads((tmp_path / "b.json").read_text())["reference"] == [3]


@pytest.mark.parametrize(("edit", "key"), [
    (lambda d: d.update(format="other"), "format"),
    (lambda d: d["radars"]["2"].update(range_gain=5.0), "radars.2.range_gain"),
    (lambda d: d["radars"]["2"].update(sigma_azimuth_deg=-1.0), "radars.2.sigma_azimuth_deg"),
    (lambda d: d["radars"]["2"].pop("azimuth_deg"), "radars.2.azimuth_deg"),
    (lambda d: d["radars"].update(x={}), "radars.x"),
])
def test_bad_fields_name_the_key(tmp_path, edit, key) -> None:
    write_biases(tmp_path / "b.json", {2: RadarBias(1.0, 1.0, 0.1, (1.0, 1e-4, 0.01))})
    d = json.loads((tmp_path / "b.json").read_text())
    edit(d)
    (tmp_path / "b.json").write_text(json.dumps(d))
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        read_biases(tmp_path / "b.json")
