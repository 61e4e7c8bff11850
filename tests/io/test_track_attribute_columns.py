"""The tracks file's attribute columns (:mod:`mhtrack.io.track_attributes`): written and
read back equal, absent values empty, files without attributes as before, bad cells
located."""

import numpy as np
import pytest

from mhtrack.attributes import TrackAttributes
from mhtrack.errors import InputError
from mhtrack.io.tracks import read_tracks, write_tracks
from mhtrack.records import TrackTable


def _table(n=4, attrs=True):
    rng = np.random.default_rng(2)
    a = TrackAttributes(
        flight_level=np.array([350.0, np.nan, 120.25, -5.0])[:n],
        rate_of_climb=np.array([0.0, np.nan, -1500.0, 312.5])[:n],
        mode_3a=np.array([0o1174, -1, 0o7700, 0])[:n],
        address=np.array([0x3C4591, -1, 0xABCDEF, 0x000001])[:n],
        callsign=np.array(["BOX413", "", "DLH4AB", "A"], object)[:n],
        sigma_major=np.array([30.5, np.nan, 120.0, 1.0])[:n],
        sigma_minor=np.array([3.25, np.nan, 100.0, 1.0])[:n],
        sigma_orient=np.array([116.8, np.nan, 0.0, 179.5])[:n],
        sensors=np.array(["1;3", "", "0", "2"], object)[:n],
        sensor_ages=np.array(["0.000;12.250", "", "4.000", "0.500"], object)[:n],
        age_psr=np.array([0.0, np.nan, 4.0, np.nan])[:n],
        age_ssr=np.array([12.25, np.nan, np.nan, 0.5])[:n],
        age_mds=np.array([np.nan, np.nan, 4.0, 0.5])[:n],
        meas_sensor=np.array([6412, -1, 3, 4])[:n],
        meas_type=np.array([4, 0, 1, 3])[:n],
        meas_mode_3a=np.array([0o1174, -1, -1, 0o7700])[:n],
        meas_mode_3a_vg=np.array([0, 0, 0, 3])[:n],
        meas_flight_level=np.array([350.25, np.nan, np.nan, -5.0])[:n],
        meas_flight_level_vg=np.array([2, 0, 0, 1])[:n],
        meas_range=np.array([151234.5, np.nan, np.nan, 2000.0])[:n],
        meas_bearing=np.array([359.75, np.nan, np.nan, 0.0])[:n],
        existence_probability=np.array([0.5, np.nan, 0.999, 1e-6])[:n])
    return TrackTable(scan=np.arange(n), time=np.arange(n) * 1.5, track_id=np.arange(n),
                      x=rng.normal(size=n), y=rng.normal(size=n), vx=rng.normal(size=n),
                      vy=rng.normal(size=n), plot=np.array([3, -1, 5, 7])[:n],
                      score=rng.normal(size=n), attrs=a if attrs else None)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_attribute_columns_round_trip(tmp_path, suffix):
    t = _table()
    write_tracks(t, tmp_path / f"t{suffix}")
    back = read_tracks(tmp_path / f"t{suffix}")
    for name in ("flight_level", "rate_of_climb", "sigma_major", "sigma_minor",
                 "sigma_orient", "age_psr", "age_ssr", "age_mds", "meas_sensor", "meas_type",
                 "meas_mode_3a", "meas_mode_3a_vg", "meas_flight_level",
                 "meas_flight_level_vg", "meas_range", "meas_bearing",
                 "existence_probability"):
        np.testing.assert_array_equal(getattr(back.attrs, name), getattr(t.attrs, name))
    for name in ("mode_3a", "address", "callsign", "sensors", "sensor_ages"):
        assert getattr(back.attrs, name).tolist() == getattr(t.attrs, name).tolist()


def test_csv_cells_as_written(tmp_path):
    write_tracks(_table(), tmp_path / "t.csv")
    lines = (tmp_path / "t.csv").read_text().splitlines()
    head = lines[0].split(",")
    assert head[-22:] == ["flight_level", "rate_of_climb", "mode_3a", "address", "callsign",
                          "sigma_major", "sigma_minor", "sigma_orient", "sensors",
                          "sensor_ages", "age_psr", "age_ssr", "age_mds", "meas_sensor",
                          "meas_type", "meas_mode_3a", "meas_mode_3a_vg",
                          "meas_flight_level", "meas_flight_level_vg", "meas_range",
                          "meas_bearing", "existence_probability"]
    assert lines[1].split(",")[-22:] == ["350", "0", "1174", "3C4591", "BOX413", "30.5",
                                         "3.25", "116.8", "1;3", "0.000;12.250", "0",
                                         "12.25", "", "6412", "mode_s", "1174", "0",
                                         "350.25", "2", "151234.5", "359.75", "0.5"]
    assert lines[2].split(",")[-22:] == [""] * 22  # nothing known: empty cells
    assert lines[4].split(",")[-20:-17] == ["0000", "000001", "A"]


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_without_attributes_the_file_is_as_before(tmp_path, suffix):
    write_tracks(_table(attrs=False), tmp_path / f"t{suffix}")
    back = read_tracks(tmp_path / f"t{suffix}")
    assert back.attrs is None
    if suffix == ".csv":
        assert (tmp_path / "t.csv").read_text().splitlines()[0] == \
            "scan,time,track_id,x,y,vx,vy,plot,score"


@pytest.mark.parametrize(("column", "value", "message"), [
    ("mode_3a", "1184", "not four octal digits"),
    ("address", "XYZ", "address"),
    ("sigma_minor", "40", "exceeds"),
    ("sigma_orient", "180", "outside"),
    ("sigma_major", "-1", "negative"),
    ("sensor_ages", "1.0", "one age"),
    ("sensor_ages", "x;1", "not numbers"),
    ("sensors", "a;3", "not ids"),
    ("existence_probability", "1.5", "outside [0, 1]"),
    ("meas_bearing", "360", "outside [0, 360)"),
    ("meas_range", "-3", "negative"),
])
def test_a_bad_cell_is_located(tmp_path, column, value, message):
    write_tracks(_table(), tmp_path / "t.csv")
    lines = (tmp_path / "t.csv").read_text().splitlines()
    head = lines[0].split(",")
    cells = lines[1].split(",")
    cells[head.index(column)] = value
    lines[1] = ",".join(cells)
    (tmp_path / "t.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError) as e:
        read_tracks(tmp_path / "t.csv", accept_truth=False)
    text = str(e.value)
    assert "line 2" in text and message in text, text
    assert column in text or column == "sensors", text


def test_a_plot_bearing_of_360_reads_back(tmp_path):
    """A plot at bearing 360° (accepted by the timed plots reader; ``np.mod(-1e-17, 360)``
    gives it) is carried as 0° (north), so the tracks file written reads back."""
    from mhtrack.attributes import PlotAttributes
    from mhtrack.mht.track_attributes import measured

    assert np.mod(-1e-17, 360.0) == 360.0
    plots = PlotAttributes.absent(3)
    plots = PlotAttributes.from_columns({**plots.columns(polar=True),
                                         "polar_range": np.array([1e4, 2e4, 3e4]),
                                         "polar_bearing": np.array([360.0, 359.5, 0.0])}, 3)
    m = measured(plots, np.array([0, 1, 2, -1]), np.array([1, 1, 1]))
    assert m["meas_bearing"][:3].tolist() == [0.0, 359.5, 0.0]
    t = _table()
    t.attrs.meas_bearing[:] = m["meas_bearing"]
    write_tracks(t, tmp_path / "t.csv")
    np.testing.assert_array_equal(read_tracks(tmp_path / "t.csv").attrs.meas_bearing,
                                  m["meas_bearing"])
