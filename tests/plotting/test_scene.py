"""Scene and clutter-map figures (``mhtrack.plotting.scene``, ``plotting.clutter``)."""

import subprocess
import sys

import numpy as np
from matplotlib.figure import Figure

from mhtrack.models.clutter import Region
from mhtrack.plotting.clutter import plot_intensity_maps, save_maps
from mhtrack.plotting.scene import draw_tracks, plot_scene, save_figure
from mhtrack.records import TrackTable


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
