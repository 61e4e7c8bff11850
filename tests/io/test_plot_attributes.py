"""The attribute columns of plots files: written and read back equal (CSV, Parquet; scans
and timed plots), text forms by hand, located errors for bad cells, and the simulator's
attributes (positions untouched, the OpenSky data's own addresses)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mhtrack.attributes import (
    ABSENT,
    PlotAttributes,
    address_text,
    address_value,
    code_text,
    code_value,
)
from mhtrack.errors import InputError
from mhtrack.io import read_plots, write_plots
from mhtrack.records import PlotTable


def _attrs(n: int, rng: np.random.Generator) -> PlotAttributes:
    some = rng.random(n) < 0.7
    return PlotAttributes.from_columns({
        "plot_type": rng.integers(0, 5, n),
        "mode_3a": np.where(some, rng.integers(0, 1 << 12, n), ABSENT),
        "mode_3a_v": rng.integers(0, 2, n), "mode_3a_g": rng.integers(0, 2, n),
        "flight_level": np.where(some, rng.integers(0, 1600, n) / 4, np.nan),
        "flight_level_v": rng.integers(0, 2, n), "flight_level_g": rng.integers(0, 2, n),
        "address": np.where(some, rng.integers(0, 1 << 24, n), ABSENT),
        "callsign": np.array([f"AB{i}" if s else "" for i, s in enumerate(some)], object),
        "amplitude": np.where(some, rng.normal(-70, 5, n), np.nan),
    }, n)


def _same(a: PlotAttributes, b: PlotAttributes) -> None:
    for name, v in a.columns().items():
        w = getattr(b, name)
        assert np.array_equal(v, w, equal_nan=v.dtype.kind == "f"), name


def test_text_forms_by_hand() -> None:
    assert code_value("7000") == 0o7000 == 3584 and code_text(3584) == "7000"
    assert code_value("0036") == 30 and code_text(30) == "0036"
    assert address_value("3C4591") == 0x3C4591 and address_text(0x3C4591) == "3C4591"
    assert address_text(0x12) == "000012" and code_value("") == ABSENT
    for bad in ("7008", "700", "70000", "12a4"):
        with pytest.raises(ValueError):
            code_value(bad)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
@pytest.mark.parametrize("timed", [False, True])
def test_round_trip(tmp_path: Path, suffix: str, timed: bool) -> None:
    rng = np.random.default_rng(4)
    n = 50
    t = np.sort(rng.uniform(0, 100, n))
    table = PlotTable(scan=np.arange(n) // 5,
                      time=t if timed else (np.arange(n) // 5).astype(float),
                      sensor=np.zeros(n, np.int64), x=rng.normal(size=n),
                      y=rng.normal(size=n), timed=timed, attrs=_attrs(n, rng))
    path = tmp_path / f"p{suffix}"
    write_plots(table, path)
    back = read_plots(path)
    assert back.attrs is not None
    order = np.argsort(back.file_row) if back.file_row is not None else slice(None)
    _same(table.attrs, back.attrs.take(order))


def test_no_attribute_columns_no_attributes(tmp_path: Path) -> None:
    (tmp_path / "p.csv").write_text("scan,time,sensor,x,y\n0,0,0,1,2\n")
    assert read_plots(tmp_path / "p.csv").attrs is None


@pytest.mark.parametrize(("column", "cell", "words"), [
    ("mode_3a", "7009", "four octal digits"),
    ("address", "XYZ", "address"),
    ("plot_type", "psr", "plot type"),
    ("mode_3a_g", "2", "not 0 or 1"),
    ("flight_level", "5000", "outside"),
])
def test_bad_cells_are_located(tmp_path: Path, column: str, cell: str, words: str) -> None:
    p = tmp_path / "p.csv"
    p.write_text(f"scan,time,sensor,x,y,{column}\n0,0,0,1,2,\n1,1,0,1,2,{cell}\n")
    with pytest.raises(InputError) as e:
        read_plots(p)
    text = str(e.value)
    assert str(p) in text and column in text and words in text and "line 3" in text


def test_simulated_attributes_keep_the_plots() -> None:
    from mhtrack.scenario import preset, simulate
    from mhtrack.scenario.identity import (
        AttributeOptions,
        add_attributes,
        opensky_identities,
    )
    from mhtrack.scenario.opensky import load_opensky

    sim = simulate(preset("opensky-radars", scans=6), seed=3)
    ids = opensky_identities()
    with_attrs = add_attributes(sim.plots, ids, AttributeOptions(), 3)
    for f in ("scan", "time", "sensor", "x", "y", "range", "bearing", "origin", "R"):
        assert np.array_equal(getattr(with_attrs, f), getattr(sim.plots, f)), f
    a = with_attrs.attrs
    clutter = sim.plots.origin < 0
    assert (a.plot_type[clutter] == 1).all() and (a.address[clutter] == ABSENT).all()
    icao = load_opensky().icao24
    target = ~clutter & (a.address >= 0)
    assert target.any()
    for o, addr in zip(sim.plots.origin[target].tolist(), a.address[target].tolist(),
                       strict=True):
        assert addr == int(icao[o - 1], 16)  # the data's own address of the aircraft
    assert np.isnan(a.flight_level[a.plot_type == 1]).all()  # primary plots: no reply


def test_scan_plots_with_attributes_and_cartesian_nan_rows(tmp_path: Path) -> None:
    """A Cartesian sensor's row may write ``nan`` range/bearing (docs/file-formats.md) also
    when the file has attribute columns; the polar row's measured position is the SLANT
    range of its ground range at its flight level (a scenario's flat frame: by hand
    √(4000² + (100 FL · 30.48 m)²) = 5000.6 m), the Cartesian row's NaN."""
    from mhtrack.models.sensors import CartesianSensor, PolarRadar

    p = tmp_path / "plots.csv"
    p.write_text("scan,time,sensor,x,y,range,bearing,mode_3a,flight_level\n"
                 "1,0,0,10,20,nan,nan,1234,\n"
                 "1,0,1,0,4000,4000,0,7000,100\n")
    t = read_plots(p, {0: CartesianSensor(0), 1: PolarRadar(1)})
    a = t.attrs
    assert t.sensor.tolist() == [0, 1]
    assert a.mode_3a.tolist() == [code_value("1234"), code_value("7000")]
    assert np.isnan(a.polar_range[0]) and np.isnan(a.polar_bearing[0])
    assert a.polar_range[1] == pytest.approx(np.hypot(4000.0, 3048.0), rel=1e-12)
    assert a.polar_bearing[1] == 0.0


def test_a_clutter_scene_keeps_the_opensky_identities() -> None:
    """``--clutter-scene`` renames the scenario (``opensky-radars+storm``); its targets
    are still the OpenSky data's aircraft, with their own addresses."""
    from mhtrack.scenario import preset, simulate
    from mhtrack.scenario.identity import with_attributes
    from mhtrack.scenario.opensky import load_opensky
    from mhtrack.scenario.scenes import with_clutter_scene

    sc = with_clutter_scene(preset("opensky-radars", scans=3), "storm")
    assert sc.name == "opensky-radars+storm"
    sim = with_attributes(simulate(sc, seed=3))
    a = sim.plots.attrs
    target = (sim.plots.origin >= 0) & (a.address >= 0)
    assert target.any()
    icao = load_opensky().icao24
    assert a.address[target].tolist() == [int(icao[o - 1], 16)
                                          for o in sim.plots.origin[target].tolist()]
