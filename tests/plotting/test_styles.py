"""Curves of several methods are told apart by line style and marker, not colour alone,
and legends cover neither curves nor tracks."""

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg

from mhtrack.plotting.metrics import plot_ospa_cardinality
from mhtrack.plotting.p1 import mean_curves_figure
from mhtrack.plotting.scene import plot_scene
from mhtrack.plotting.styles import CURVE_STYLES, curve_style
from mhtrack.plotting.theta import theta_curves_figure
from mhtrack.records import TrackTable, TruthTable

SCANS = list(range(1, 61))
SAME = {"scans": SCANS, "ospa": [80.0] * 60, "ospa_std": [5.0] * 60,
        "cardinality": [4.0] * 60, "cardinality_std": [0.1] * 60,
        "cardinality_true": [4] * 60}


def method_lines(ax, labels):
    return {ln.get_label(): ln for ln in ax.get_lines() if ln.get_label() in labels}


def assert_distinguishable(ax, labels=("mht-gmm", "mht-agmm"), shifted=True):
    lines = method_lines(ax, labels)
    a, b = (lines[label] for label in labels)
    assert a.get_linestyle() != b.get_linestyle()
    assert a.get_marker() != b.get_marker()
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert set(labels) <= set(legend)
    if shifted:  # identical long curves: their markers fall on different points
        assert a.get_markevery() != b.get_markevery()


def legend_outside_axes(fig, ax):
    FigureCanvasAgg(fig).draw()
    r = fig.canvas.get_renderer()
    box, frame = ax.get_legend().get_window_extent(r), ax.get_window_extent(r)
    return not box.overlaps(frame)


def test_coinciding_gmm_and_agmm_curves_are_told_apart():
    fig = plot_ospa_cardinality({"mht-gmm": SAME, "mht-agmm": SAME}, cutoff=500.0)
    for ax in fig.axes:
        assert_distinguishable(ax)
        assert legend_outside_axes(fig, ax)
    fig = mean_curves_figure({"mht-gmm": SAME, "mht-agmm": SAME}, "ospa", ylabel="OSPA",
                             title="t", band_alpha=0.2, truth_key=None)
    assert_distinguishable(fig.axes[0])
    assert legend_outside_axes(fig, fig.axes[0])
    fig = theta_curves_figure([0.0, 10.0, 20.0], {"a": [0.1, 0.2, 0.3], "b": [0.1, 0.2, 0.3]},
                              ylabel="p", title="T")
    assert_distinguishable(fig.axes[0], ("a", "b"), shifted=False)  # hollow markers


def test_styles_differ_for_as_many_curves_as_listed():
    styles = [curve_style(j, 90, len(CURVE_STYLES)) for j in range(len(CURVE_STYLES))]
    assert len({(str(s["ls"]), s["marker"]) for s in styles}) == len(CURVE_STYLES)
    assert len({s["markevery"] for s in styles}) == len(CURVE_STYLES)


def test_scene_legend_is_below_the_axes_not_over_the_tracks():
    t = np.arange(1, 11)
    truth = TruthTable(t, t.astype(float), np.ones(10, int), 500.0 * t, 300.0 * t,
                       np.zeros(10), np.zeros(10))
    tracks = TrackTable(t, t.astype(float), np.ones(10, int), 500.0 * t + 20, 300.0 * t,
                        np.zeros(10), np.zeros(10), np.full(10, -1))
    fig = plot_scene(truth=truth, tracks=tracks)
    ax = fig.axes[0]
    assert {"truth", "tracks"} <= {t.get_text() for t in ax.get_legend().get_texts()}
    assert legend_outside_axes(fig, ax)
