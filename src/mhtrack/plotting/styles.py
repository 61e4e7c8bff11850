"""How curves of several methods are told apart, and where legends go.

Curves of two methods can coincide (``mht-gmm`` and ``mht-agmm`` give the same tracks on
most ``crossing`` runs), so colour alone is not enough: the ``j``-th curve of a figure
gets the ``j``-th line style **and** marker of :data:`CURVE_STYLES`, its markers shifted
along the curve so that those of coinciding curves do not hide each other. Legends go
outside the axes (:func:`legend_outside`), where they cover no curve or track.
"""

from __future__ import annotations

from typing import Any

from matplotlib.axes import Axes
from matplotlib.transforms import ScaledTranslation

#: ``(line style, marker)`` of curve ``j`` (cycled).
CURVE_STYLES: tuple[tuple[str, str], ...] = (
    ("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"), ((0, (5, 1, 1, 1)), "v"), ("-", "x"))
#: How far (inches) under the axes a legend below them starts: below the tick labels and
#: the x label, whatever the size of the axes.
BELOW_AXES_IN = 0.5
#: About this many markers per curve.
MARKERS_PER_CURVE = 12


def curve_style(j: int, n_points: int, n_curves: int = 1) -> dict[str, Any]:
    """``Axes.plot`` keywords of curve ``j`` of ``n_curves`` over ``n_points`` points:
    line style, marker, and a marker every ``step`` points starting ``j·step/n_curves``
    points in."""
    ls, marker = CURVE_STYLES[j % len(CURVE_STYLES)]
    step = max(1, n_points // MARKERS_PER_CURVE)
    start = (j % max(n_curves, 1)) * step // max(n_curves, 1)
    return {"ls": ls, "marker": marker, "ms": 4.5, "mfc": "none",
            "markevery": (min(start, max(n_points - 1, 0)), step)}


def legend_outside(ax: Axes, **kwargs: Any) -> None:
    """The legend of ``ax`` to the right of its axes, top-aligned (nothing if empty)."""
    if not ax.get_legend_handles_labels()[0]:
        return
    kwargs.setdefault("fontsize", 8)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, **kwargs)


def legend_below(ax: Axes, **kwargs: Any) -> None:
    """The legend of ``ax`` under its axes (and under the x label), in up to 3 columns —
    for pictures of a scene, whose side panels sit to the right (nothing if empty)."""
    handles, _ = ax.get_legend_handles_labels()
    if not handles:
        return
    kwargs.setdefault("fontsize", 8)
    kwargs.setdefault("ncol", min(3, len(handles)))
    below = ax.transAxes + ScaledTranslation(0.0, -BELOW_AXES_IN, ax.figure.dpi_scale_trans)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below,
              borderaxespad=0.0, **kwargs)
