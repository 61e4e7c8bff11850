"""Scene and clutter-map figures (``mhtrack.plotting.scene``, ``plotting.clutter``)."""

import subprocess
import sys

import numpy as np
import pytest
from matplotlib.figure import Figure

from mhtrack.models.clutter import Region
from mhtrack.plotting.clutter import plot_intensity_maps, save_maps
from mhtrack.plotting.scene import draw_tracks, plot_scene, save_figure, sensor_sites
from mhtrack.records import TrackTable, TruthTable


def _tracks(tentative):
    n = 5
    scan = np.arange(1, n + 1)
    x = scan * 10.0
    return TrackTable(scan, scan.astype(float), np.full(n, 7), x, -x, np.zeros(n),
                      np.zeros(n), np.full(n, -1), tentative=tentative)


def test_tentative_rows_are_dotted_and_join_the_confirmed_line():
    ax = Figure().add_subplot()
    draw_tracks(ax, _tracks(np.array([True, True, False, False, False])))
    dotted = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"]
    solid = [ln for ln in ax.get_lines() if ln.get_linestyle() == "-"]
    assert len(dotted) == 1 and len(solid) == 1
    assert dotted[0].get_xdata().tolist() == [10.0, 20.0, 30.0]  # up to the first confirmed
    assert solid[0].get_xdata().tolist() == [30.0, 40.0, 50.0]
    assert dotted[0].get_color() == solid[0].get_color()


def test_without_flags_every_row_is_solid():
    fig = plot_scene(tracks=_tracks(None))
    lines = fig.axes[0].get_lines()
    assert [ln.get_linestyle() for ln in lines] == ["-"]
    assert lines[0].get_xdata().tolist() == [10.0, 20.0, 30.0, 40.0, 50.0]


PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_figures_save_as_png(tmp_path):
    path = save_figure(plot_scene(tracks=_tracks(None), title="t"), tmp_path / "a" / "s.png")
    assert path.read_bytes()[:8] == PNG_MAGIC
    region = Region(0.0, 10.0, 0.0, 10.0)
    true = np.full((4, 4), 1e-2)
    fig = plot_intensity_maps(true, true * 2, region, plots=np.array([[1.0, 2.0]]))
    assert len(fig.axes) == 3  # two maps and the colour bar
    assert save_maps(fig, tmp_path / "m.png").read_bytes()[:8] == PNG_MAGIC


def test_importing_the_figures_neither_switches_the_backend_nor_loads_pyplot():
    code = ("import matplotlib, sys; matplotlib.use('svg'); "
            "import mhtrack.plotting.scene, mhtrack.plotting.clutter; "
            "print(matplotlib.get_backend(), 'matplotlib.pyplot' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.split() == ["svg", "False"]


# ---------------------------------------------------------------- geographic scenes


def _wide_truth(span_m):
    """One target flying ``span_m`` east (two rows)."""
    return TruthTable(np.array([0, 1]), np.array([0.0, 1.0]), np.array([1, 1]),
                      np.array([0.0, span_m]), np.array([0.0, 0.0]), np.zeros(2), np.zeros(2))


def _tick_labels(fig):
    fig.canvas.draw()  # Agg canvas of a plain Figure: formats the tick labels
    ax = fig.axes[0]
    return [t.get_text() for t in ax.get_xticklabels()], [t.get_text() for t in
                                                            ax.get_yticklabels()]


def test_wide_scenes_are_drawn_in_km_and_small_ones_in_m():
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    wide = plot_scene(truth=_wide_truth(300_000.0))
    FigureCanvasAgg(wide)
    ax = wide.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x east (km)", "y north (km)")
    xt, _ = _tick_labels(wide)
    # every label is the tick's position in metres divided by 1000
    for loc, text in zip(ax.get_xticks(), xt, strict=True):
        assert float(text.replace("\u2212", "-")) == pytest.approx(loc / 1000)
    assert any(float(t.replace("\u2212", "-")) == 300 for t in xt)
    small = plot_scene(truth=_wide_truth(8_000.0))  # P1's crossing region: 8 km
    assert small.axes[0].get_xlabel() == "x east (m)"
    forced = plot_scene(truth=_wide_truth(8_000.0), units="km")
    assert forced.axes[0].get_xlabel() == "x east (km)"
    # multiradar's ≈ 14 km: five-digit metre ticks read worse than km
    assert plot_scene(truth=_wide_truth(15_000.0)).axes[0].get_xlabel() == "x east (km)"
    assert plot_scene().axes[0].get_xlabel() == "x east (m)"  # nothing drawn: metres
    with pytest.raises(ValueError, match="units"):
        plot_scene(units="mi")


def test_radar_sites_are_drawn_and_labelled():
    sites = [(-50_000.0, 10_000.0, "radar 1"), (60_000.0, -20_000.0, "radar 2")]
    fig = plot_scene(truth=_wide_truth(30_000.0), sites=sites)
    ax = fig.axes[0]
    (marks,) = [ln for ln in ax.get_lines() if ln.get_label() == "radar sites"]
    assert marks.get_marker() == "^"
    assert marks.get_xdata().tolist() == [-50_000.0, 60_000.0]
    assert marks.get_ydata().tolist() == [10_000.0, -20_000.0]
    assert [t.get_text() for t in ax.texts] == ["radar 1", "radar 2"]
    assert "radar sites" in [t.get_text() for t in ax.get_legend().get_texts()]
    assert ax.get_xlabel() == "x east (km)"  # the sites widen the scene beyond 10 km


def test_sensor_sites_come_from_the_sensor_set():
    from mhtrack.models.geodesy import LocalFrame
    from mhtrack.models.radars import RadarSensor, SensorSet

    s = SensorSet(origin=(46.8, 8.2), sensors=(
        RadarSensor(1, "polar", pd=0.9, lat=46.8, lon=8.2, sigma_range=80.0,
                    sigma_bearing_deg=0.15),
        RadarSensor(2, "cartesian", pd=0.9, position=(1000.0, -2000.0), sigma=50.0),
        RadarSensor(3, "cartesian", pd=0.9, sigma=50.0),  # no site: not drawn
        RadarSensor(4, "polar", pd=0.9, lat=47.0, lon=8.2, sigma_range=80.0,
                    sigma_bearing_deg=0.15),
    ))
    got = sensor_sites(s)
    assert [g[2] for g in got] == ["radar 1", "radar 2", "radar 4"]
    assert got[0][:2] == pytest.approx((0.0, 0.0), abs=1e-6)  # the origin itself
    assert got[1][:2] == (1000.0, -2000.0)
    x4, y4 = LocalFrame(46.8, 8.2).to_local(47.0, 8.2)  # due north of the origin
    assert got[2][:2] == pytest.approx((float(x4), float(y4)))
    assert 22_000 < got[2][1] < 22_400 and abs(got[2][0]) < 1e-6  # 0.2° of latitude ≈ 22.2 km
