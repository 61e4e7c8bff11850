"""Scene figures (``mhtrack.plotting.scene``)."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from mhtrack.plotting.scene import draw_tracks, plot_scene
from mhtrack.records import TrackTable


def _tracks(tentative):
    n = 5
    scan = np.arange(1, n + 1)
    x = scan * 10.0
    return TrackTable(scan, scan.astype(float), np.full(n, 7), x, -x, np.zeros(n),
                      np.zeros(n), np.full(n, -1), tentative=tentative)


def test_tentative_rows_are_dotted_and_join_the_confirmed_line():
    fig, ax = plt.subplots()
    draw_tracks(ax, _tracks(np.array([True, True, False, False, False])))
    dotted = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"]
    solid = [ln for ln in ax.get_lines() if ln.get_linestyle() == "-"]
    assert len(dotted) == 1 and len(solid) == 1
    assert dotted[0].get_xdata().tolist() == [10.0, 20.0, 30.0]  # up to the first confirmed
    assert solid[0].get_xdata().tolist() == [30.0, 40.0, 50.0]
    assert dotted[0].get_color() == solid[0].get_color()
    plt.close(fig)


def test_without_flags_every_row_is_solid():
    fig = plot_scene(tracks=_tracks(None))
    lines = fig.axes[0].get_lines()
    assert [ln.get_linestyle() for ln in lines] == ["-"]
    assert lines[0].get_xdata().tolist() == [10.0, 20.0, 30.0, 40.0, 50.0]
    plt.close(fig)
