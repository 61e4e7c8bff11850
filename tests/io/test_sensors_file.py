"""The sensors file: a valid file reads (and writes back) exactly; each bad case raises one
InputError naming the file, the line and the key — checked verbatim."""

from __future__ import annotations

import pytest

from mhtrack.errors import InputError
from mhtrack.io.sensors import read_sensors, write_sensors
from mhtrack.models.geodesy import LocalFrame
from mhtrack.models.radars import RadarSensor, SensorFieldError, SensorSet

VALID = """\
[origin]                 # optional: tangent point of the local east-north frame
lat = 46.8
lon = 8.2
[[sensors]]
id = 1
kind = "polar"           # a comment
lat = 46.4253
lon = 6.0989
alt = 1600.0
sigma_range = 80.0
sigma_bearing_deg = 0.15
pd = 0.9
period = 12.0
max_range = 220000.0

[[sensors]]
id = 2
kind = "cartesian"
sigma = 50.0
pd = 1.0
"""


def edit(changes: dict[int, str | None]) -> str:
    """VALID with its (1-based) lines replaced as ``changes`` says (``None``: blanked, so
    that the other lines keep their numbers)."""
    lines = VALID.splitlines()
    for k, new in changes.items():
        lines[k - 1] = "" if new is None else new
    return "\n".join(lines) + "\n"


def write(tmp_path, text: str | bytes):
    path = tmp_path / "sensors.toml"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    return path


def test_valid_file_reads_exactly(tmp_path):
    s = read_sensors(write(tmp_path, VALID))
    assert s.origin == (46.8, 8.2)
    assert s.sensors == (
        RadarSensor(1, "polar", lat=46.4253, lon=6.0989, alt=1600.0, sigma_range=80.0,
                    sigma_bearing_deg=0.15, pd=0.9, period=12.0, max_range=220000.0),
        RadarSensor(2, "cartesian", sigma=50.0, pd=1.0),
    )
    assert s.frame() == LocalFrame(46.8, 8.2)
    assert s.site_latlon(1) == (46.4253, 6.0989)
    x, y = s.site_xy(1)
    assert s.frame().to_geodetic(x, y) == pytest.approx((46.4253, 6.0989), abs=1e-12)
    with pytest.raises(KeyError, match="unknown sensor 7"):
        s.sensor(7)
    write_sensors(s, tmp_path / "back.toml")
    assert read_sensors(tmp_path / "back.toml") == s


def test_default_origin_is_first_site_and_position_sites(tmp_path):
    text = edit({1: None, 2: None, 3: None})
    text += '[[sensors]]\nid = 3\nkind = "polar"\nposition = [1000.0, -2000.0]\n' \
            "sigma_range = 30\nsigma_bearing_deg = 0.2\npd = 0.8\n"
    s = read_sensors(write(tmp_path, text))
    assert s.origin is None
    assert s.frame() == LocalFrame(46.4253, 6.0989)
    assert s.site_xy(1) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert s.site_xy(3) == (1000.0, -2000.0)
    lat, lon = s.site_latlon(3)
    assert s.frame().to_local(lat, lon) == pytest.approx((1000.0, -2000.0), abs=1e-6)


def test_inline_tables_read_and_are_located(tmp_path):
    text = ('origin = {lat = 46.8, lon = 8.2}\n'
            'sensors = [{id = 1, kind = "cartesian", sigma = 10, pd = 0.5},\n'
            '           {id = 1, kind = "cartesian", sigma = 10, pd = 0.5}]\n')
    with pytest.raises(InputError) as e:
        read_sensors(write(tmp_path, text))
    assert e.value.line == 2  # inline tables are located at the line opening `sensors`
    assert "key 'sensors[1].id': duplicate id 1" in str(e.value)


# (id, line to edit, its new text or None to blank it, expected line, expected message)
# (id, {line: new text or None to blank it}, expected line, expected message)
CASES = [
    ("missing pd", {20: None}, 16, "key 'sensors[1].pd': missing (required for every sensor)"),
    ("missing id", {5: None}, 4, "key 'sensors[0].id': missing (required for every sensor)"),
    ("missing sigma_range", {10: None}, 4,
     "key 'sensors[0].sigma_range': missing: required for a polar sensor"),
    ("missing sigma", {19: None}, 16,
     "key 'sensors[1].sigma': missing: required for a cartesian sensor"),
    ("missing origin lon", {3: None}, 1, "key 'origin.lon': missing"),
    ("misspelt key", {11: "sigma_bearing = 0.15"}, 11,
     "key 'sensors[0].sigma_bearing': unknown key; did you mean 'sigma_bearing_deg'?"),
    ("misspelt origin key", {3: "lng = 8.2"}, 3,
     "key 'origin.lng': unknown key; did you mean 'lon'?"),
    ("misspelt table", {1: "[orgin]"}, 1, "key 'orgin': unknown key; did you mean 'origin'?"),
    ("unknown key", {9: "colour = 'red'"}, 9,
     "key 'sensors[0].colour': unknown key; known keys: id, kind, pd, lat, lon, alt, position, "
     "sigma_range, sigma_bearing_deg, sigma, period, max_range, primary, secondary, "
     "combined, mode_s"),
    ("latitude 95", {7: "lat = 95.0"}, 7,
     "key 'sensors[0].lat': latitude must be within [-90, 90] degrees, got 95"),
    ("origin latitude -95", {2: "lat = -95"}, 2,
     "key 'origin.lat': latitude must be within [-90, 90] degrees, got -95"),
    ("longitude 200", {8: "lon = 200.0"}, 8,
     "key 'sensors[0].lon': longitude must be within [-180, 180] degrees, got 200"),
    ("origin longitude", {3: "lon = -180.5"}, 3,
     "key 'origin.lon': longitude must be within [-180, 180] degrees, got -180.5"),
    ("negative sigma_range", {10: "sigma_range = -80.0"}, 10,
     "key 'sensors[0].sigma_range': must be in [1e-09, 1e6] m, got -80"),
    ("negative sigma_bearing", {11: "sigma_bearing_deg = -0.1"}, 11,
     "key 'sensors[0].sigma_bearing_deg': must be in [1e-12, 30] degrees, got -0.1"),
    ("zero sigma", {19: "sigma = 0"}, 19,
     "key 'sensors[1].sigma': must be in [1e-09, 1e6] m, got 0"),
    ("pd zero", {12: "pd = 0.0"}, 12, "key 'sensors[0].pd': must be in (0, 1], got 0"),
    ("pd above one", {20: "pd = 1.5"}, 20, "key 'sensors[1].pd': must be in (0, 1], got 1.5"),
    ("pd nan", {12: "pd = nan"}, 12, "key 'sensors[0].pd': must be finite, got nan"),
    ("duplicate id", {17: "id = 1"}, 17, "key 'sensors[1].id': duplicate id 1 (also sensors[0])"),
    ("lat without lon", {8: None}, 4,
     "key 'sensors[0].lon': missing: lat and lon give the site together"),
    ("site twice", {9: "position = [1.0, 2.0]"}, 9,
     "key 'sensors[0].position': give the site once: lat/lon or position"),
    ("period zero", {13: "period = 0"}, 13, "key 'sensors[0].period': must be > 0, got 0"),
    ("max_range negative", {14: "max_range = -1.0"}, 14,
     "key 'sensors[0].max_range': must be > 0, got -1"),
    ("sigma on polar", {9: "sigma = 5.0"}, 9,
     "key 'sensors[0].sigma': not used by a polar sensor"),
    ("kind", {18: 'kind = "optical"'}, 18,
     "key 'sensors[1].kind': must be 'polar', 'cartesian' or 'adsb', got 'optical'"),
    ("pd string", {12: 'pd = "0.9"'}, 12,
     "key 'sensors[0].pd': expected a number, got string '0.9'"),
    ("id float", {17: "id = 2.0"}, 17, "key 'sensors[1].id': expected an integer, got float 2.0"),
    ("id boolean", {17: "id = true"}, 17,
     "key 'sensors[1].id': expected an integer, got boolean True"),
    ("kind number", {6: "kind = 1"}, 6, "key 'sensors[0].kind': expected a string, got integer 1"),
    ("position type", {9: 'position = [1.0, "a"]'}, 9,
     "key 'sensors[0].position': expected [x, y], two numbers, got array [1.0, 'a']"),
    ("origin not a table", {1: "origin = 4", 2: None, 3: None}, 1,
     "key 'origin': expected a table, got integer 4"),
    # physically impossible geometry (issue 33): refused at the key
    ("altitude in km units", {9: "alt = 1.6e6"}, 9,
     "key 'sensors[0].alt': altitude 1.6e+06 m is not physically possible for a site "
     "(expected [-500, 100000] m; a unit error?)"),
    ("altitude below the sea", {9: "alt = -11000"}, 9,
     "key 'sensors[0].alt': altitude -11000 m is not physically possible for a site "
     "(expected [-500, 100000] m; a unit error?)"),
    # the antipode of (46.4253, 6.0989); 20 004 km by GeographicLib
    ("origin at the antipode", {2: "lat = -46.4253", 3: "lon = -173.9011"}, 7,
     "key 'sensors[0].lat': site (46.4253, 6.0989) is 20004 km from [origin] at "
     "(-46.4253, -173.901), farther than 3000 km: the local plane cannot hold it (wrong "
     "origin or a sign error in lat/lon?)"),
    ("site 30 degrees of latitude from the origin (3327 km by GeographicLib)",
     {7: "lat = 16.8", 8: "lon = 8.2"}, 7,
     "key 'sensors[0].lat': site (16.8, 8.2) is 3327 km from [origin] at (46.8, 8.2), "
     "farther than 3000 km: the local plane cannot hold it (wrong origin or a sign error "
     "in lat/lon?)"),
    ("position far from the origin", {7: None, 8: None, 9: "position = [3e6, 1e5]"}, 9,
     "key 'sensors[0].position': site 3002 km from the frame's origin, farther than "
     "3000 km (the local plane cannot hold it)"),
    ("max_range beyond half the Earth", {14: "max_range = 3e7"}, 14,
     "key 'sensors[0].max_range': 3e+07 m is beyond 20000 km, half-way round the Earth"),
    ("bearing error that underflows", {11: "sigma_bearing_deg = 1e-300"}, 11,
     "key 'sensors[0].sigma_bearing_deg': must be in [1e-12, 30] degrees, got 1e-300"),
]


@pytest.mark.parametrize(("changes", "expected_line", "message"),
                         [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_sensors_file(tmp_path, changes, expected_line, message):
    path = write(tmp_path, edit(changes))
    with pytest.raises(InputError) as e:
        read_sensors(path)
    assert str(e.value) == f"{path}, line {expected_line}, {message}"
    assert e.value.line == expected_line
    assert e.value.file == str(path)


def test_polar_by_position_needs_a_geodetic_reference(tmp_path):
    text = ('[[sensors]]\nid = 4\nkind = "cartesian"\nsigma = 1\npd = 1\n'
            '[[sensors]]\nid = 5\nkind = "polar"\nposition = [0, 0]\nsigma_range = 1\n'
            'sigma_bearing_deg = 1\npd = 1\n')
    path = write(tmp_path, text)
    with pytest.raises(InputError) as e:
        read_sensors(path)
    assert str(e.value).startswith(f"{path}, line 9, key 'sensors[1].position': a polar "
                                   "sensor placed by position needs [origin]")


def test_no_sensors(tmp_path):
    path = write(tmp_path, "[origin]\nlat = 1\nlon = 2\n")
    with pytest.raises(InputError) as e:
        read_sensors(path)
    assert str(e.value) == (f"{path}, key 'sensors': expected one or more [[sensors]] "
                            "tables, missing")


def test_not_utf8_and_syntax_errors_name_file_and_line(tmp_path):
    path = write(tmp_path, edit({}).encode().replace(b"# a comment", b"# caf\xe9"))
    with pytest.raises(InputError) as e:
        read_sensors(path)
    assert str(e.value) == f"{path}, line 6: not valid UTF-8 text (byte 0xe9)"
    assert e.value.line == 6
    path = write(tmp_path, edit({12: "pd = "}))
    with pytest.raises(InputError) as e:
        read_sensors(path)
    assert str(e.value).startswith(f"{path}, line 12, column ")
    assert e.value.line == 12
    with pytest.raises(InputError, match="no such file"):
        read_sensors(tmp_path / "absent.toml")


def test_dataclasses_validate_for_python_callers():
    with pytest.raises(SensorFieldError, match=r"^sensor 3: pd: must be in \(0, 1\], got 2$"):
        RadarSensor(3, "cartesian", sigma=1.0, pd=2.0)
    with pytest.raises(SensorFieldError) as e:
        SensorSet(None, (RadarSensor(1, "cartesian", sigma=1.0, pd=1.0),) * 2)
    assert (e.value.index, e.value.key) == (1, "id")
    with pytest.raises(ValueError, match="no geodetic reference"):
        SensorSet(None, (RadarSensor(1, "cartesian", sigma=1.0, pd=1.0),)).frame()


def test_polar_sensor_without_site_reads_and_its_table_plots_are_refused(tmp_path):
    """A polar radar listed with its errors only (its site to come from its ASTERIX
    CAT034 I034/120) reads; its range/bearing plots in a table are refused, one line."""
    from mhtrack.io.timed_plots import read_timed_plots

    s = read_sensors(write(tmp_path, edit({7: None, 8: None})))
    assert s.sensor(1).kind == "polar" and not s.sensor(1).has_site
    plots = tmp_path / "plots.csv"
    plots.write_text("time,sensor,range,bearing\n0.5,1,1000.0,10.0\n")
    with pytest.raises(InputError, match=r"plots\.csv, line 2, column 'sensor': sensor 1 is "
                       r"a polar radar without a site in the sensors file"):
        read_timed_plots(plots, s)
