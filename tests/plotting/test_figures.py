"""Figure modules of initiation, metrics, θ curves and P1: drawing only, no backend switch."""

import subprocess
import sys

import numpy as np
from matplotlib.figure import Figure

from mhtrack.plotting.initiation import finish_axes, zoom_to_truth
from mhtrack.plotting.metrics import plot_ospa_cardinality
from mhtrack.plotting.theta import theta_curves_figure


def test_importing_and_drawing_keeps_the_backend_and_pyplot_out(tmp_path):
    """Importing the figure modules and saving a PNG leaves the user's backend alone and
    never loads pyplot."""
    code = f"""
import matplotlib
matplotlib.use("svg")
import sys
import mhtrack.plotting.initiation, mhtrack.plotting.metrics, mhtrack.plotting.theta
from mhtrack.plotting.metrics import plot_ospa_cardinality
fig = plot_ospa_cardinality({{"a": {{"scans": [1, 2], "ospa": [1.0, 2.0],
                              "cardinality": [1, 1], "cardinality_true": [1, 1]}}}})
fig.savefig({str(tmp_path / "f.png")!r})
assert matplotlib.get_backend() == "svg", matplotlib.get_backend()
assert "matplotlib.pyplot" not in sys.modules
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"


def test_zoom_to_truth_is_the_truth_box_plus_margin():
    ax = Figure().subplots()
    zoom_to_truth(ax, np.array([[0.0, 10.0], [100.0, -20.0]]), margin=5.0)
    assert ax.get_xlim() == (-5.0, 105.0) and ax.get_ylim() == (-25.0, 15.0)
    before = ax.get_xlim()
    zoom_to_truth(ax, np.zeros((0, 2)))
    assert ax.get_xlim() == before  # nothing to zoom on: unchanged
    finish_axes(ax, "t")
    assert ax.get_title() == "t" and ax.get_xlabel() == "x east (m)"


def test_metric_and_theta_figures_draw_what_they_are_given():
    fig = plot_ospa_cardinality({"a": {"scans": [1, 2, 3], "ospa": [1.0, 2.0, 3.0],
                                       "ospa_std": [0.1, 0.1, 0.1],
                                       "cardinality": [1, 2, 2], "cardinality_true": [1, 2, 2]}},
                                cutoff=50.0)
    ax1, ax2 = fig.axes
    np.testing.assert_array_equal(ax1.lines[0].get_ydata(), [1.0, 2.0, 3.0])
    assert "c = 50" in ax1.get_ylabel()
    assert [t.get_text() for t in ax2.get_legend().get_texts()] == ["a", "truth"]
    fig = theta_curves_figure([40.0, 10.0], {"x": [0.4, 0.1]}, ylabel="p", title="T",
                              theta_mark=20.0, mark_label="mark")
    (ax,) = fig.axes
    line = ax.lines[0]
    np.testing.assert_array_equal(line.get_xdata(), [10.0, 40.0])  # sorted by θ
    np.testing.assert_array_equal(line.get_ydata(), [0.1, 0.4])
    assert ax.lines[1].get_xdata()[0] == 20.0 and ax.get_title() == "T"
