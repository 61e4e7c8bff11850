"""The scene of an HTML report as a Plotly figure: plots (clutter grey), truth, tracks,
radar sites and, for geographic scenes, a map-free latitude/longitude grid.

The same picture as :func:`mhtrack.plotting.scene.plot_scene` (P1 Figs. 2–4: truth with
``o`` at birth and ``x`` at death, tracks one colour per id), but interactive: zoom and pan
(mouse wheel, drag), hover for the id, scan and time of a point, click a legend entry to
hide it. Equal axes, in kilometres beyond :data:`~mhtrack.plotting.scene.KM_ABOVE_M`.

Every trace is an SVG ``scatter`` (no WebGL: the page renders in any browser, headless
ones included); a scene of more than :data:`MAX_PLOTS` plots is thinned deterministically
and its legend entry says so.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from mhtrack.plotting.scene import KM_ABOVE_M, Site
from mhtrack.records import PlotTable, TrackTable, TruthTable
from mhtrack.reports.html_hover import hover as hover_template
from mhtrack.reports.html_hover import row_text, track_labels

if TYPE_CHECKING:
    import plotly.graph_objects as go

    from mhtrack.models.geodesy import LocalFrame

#: Most plots of each kind drawn (SVG markers); more are thinned to every k-th plot.
#: Each marker is one SVG path: 5 000 per kind keeps a 20-minute three-radar scene's
#: drawing under half a second (docs/reports.md, *Load time*).
MAX_PLOTS = 5_000
#: Most tracks drawn as one trace each (hover, own colour); more share one trace.
MAX_TRACK_TRACES = 250
#: Most track rows drawn; more are thinned to every k-th row of each track.
MAX_TRACK_POINTS = 40_000
#: Plotly's default qualitative colours (the ``D3`` palette, as matplotlib's ``tab10``).
PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf")
#: Grid steps tried (degrees), the first giving at most :data:`GRID_LINES` lines per axis.
GRID_STEPS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0, 15.0, 30.0)
GRID_LINES = 8


#: The type of drawn coordinates: float32 (7 digits: 0.1 m at 1000 km) halves their
#: share of the page against float64. Hover data (times: POSIX seconds) stays float64.
DRAWN = np.float32


def _gapped(xs: Sequence[np.ndarray]) -> np.ndarray:
    """Concatenate polylines with a NaN between them (Plotly breaks a line at a gap)."""
    parts: list[np.ndarray] = []
    for x in xs:
        parts += [np.asarray(x, DRAWN), np.array([np.nan], DRAWN)]
    return np.concatenate(parts) if parts else np.empty(0, DRAWN)


def _segments(ids: np.ndarray, order_key: np.ndarray) -> list[np.ndarray]:
    """Row indices of each id, in ``order_key`` order within the id."""
    order = np.lexsort((order_key, ids))
    cuts = np.flatnonzero(np.diff(ids[order])) + 1
    return np.split(order, cuts) if len(order) else []


def _thin(n: int, most: int) -> np.ndarray:
    """Indices of at most ``most`` of ``n`` rows, evenly spread (deterministic)."""
    if n <= most:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, most).astype(np.int64))


def plot_traces(plots: PlotTable, scale: float, *, word: str = "scan"
                ) -> list[dict[str, Any]]:
    """Plots as markers: clutter grey and target plots blue when ``origin`` is known;
    each kind thinned to at most :data:`MAX_PLOTS` (its legend entry then says so).
    Hover: ``word`` (scan, or frame for timed plots), time and sensor."""
    hover = (f"{word} %{{customdata[0]}}, t = %{{customdata[1]:.1f}} s, sensor "
             "%{customdata[2]}<extra></extra>")
    kinds = ([("plots", np.arange(len(plots)), {"size": 3, "color": "#8c8c8c"})]
             if plots.origin is None else
             [("clutter", np.flatnonzero(plots.origin < 0), {"size": 3, "color": "#b3b3b3"}),
              ("target plots", np.flatnonzero(plots.origin >= 0),
               {"size": 4, "color": "#1f77b4", "opacity": 0.6})])
    out = []
    for name, rows, marker in kinds:
        keep = rows[_thin(len(rows), MAX_PLOTS)]
        note = "" if len(keep) == len(rows) else f" ({len(keep)} of {len(rows)} drawn)"
        out.append({"type": "scatter", "mode": "markers", "name": name + note,
                    "x": (plots.x[keep] / scale).astype(DRAWN),
                    "y": (plots.y[keep] / scale).astype(DRAWN),
                    "customdata": np.column_stack([plots.scan[keep], plots.time[keep],
                                                   plots.sensor[keep]]),
                    "hovertemplate": hover, "marker": marker})
    return out


def truth_traces(truth: TruthTable, scale: float) -> list[dict[str, Any]]:
    """Truth lines (one trace, gaps between targets), ``o`` at births and ``x`` at deaths."""
    segs = _segments(truth.target_id, truth.time)
    ids = _gapped([truth.target_id[r] for r in segs])
    line = {"type": "scatter", "mode": "lines", "name": "truth", "legendgroup": "truth",
            "x": _gapped([truth.x[r] / scale for r in segs]),
            "y": _gapped([truth.y[r] / scale for r in segs]),
            "customdata": ids, "line": {"color": "black", "width": 1.5},
            "hovertemplate": "target %{customdata}<extra></extra>"}
    ends = []
    for name, pick, symbol in (("births", 0, "circle-open"), ("deaths", -1, "x-thin-open")):
        rows = np.array([r[pick] for r in segs], dtype=np.int64)
        ends.append({"type": "scatter", "mode": "markers", "name": f"truth {name}",
                     "legendgroup": "truth", "showlegend": False,
                     "x": truth.x[rows] / scale, "y": truth.y[rows] / scale,
                     "customdata": truth.target_id[rows],
                     "hovertemplate": f"target %{{customdata}} ({name[:-1]})<extra></extra>",
                     "marker": {"symbol": symbol, "size": 8, "color": "black",
                                "line": {"width": 1.5, "color": "black"}}})
    return [line, *ends]


def _thin_rows(segs: list[np.ndarray], most: int) -> tuple[list[np.ndarray], bool]:
    """Every k-th row of each polyline (its last kept) so that at most about ``most``
    rows remain in all; whether anything was dropped."""
    total = sum(len(r) for r in segs)
    if total <= most:
        return segs, False
    k = math.ceil(total / most)
    return [np.unique(np.append(r[::k], r[-1])) if len(r) else r for r in segs], True


def track_traces(tracks: TrackTable, scale: float, details: dict[str, np.ndarray] | None
                 = None, *, word: str = "scan") -> list[dict[str, Any]]:
    """Tracks: one trace per id (its own colour, labelled at its end) up to
    :data:`MAX_TRACK_TRACES` ids, else one trace for all; rows reported before the track
    was confirmed (``tentative``, the history output) in one dotted trace; the ids at
    the tracks' ends in one text trace (a ``lines+text`` trace per track would make one
    SVG text element per row, blank or not). Hover: id,
    ``word`` (scan or frame), time and the ``details`` given per row (speed, heading,
    flight level, score, sensor; code, callsign and sensors per track —
    :func:`mhtrack.reports.html_recording.track_details`), unknown ones left out
    (:mod:`mhtrack.reports.html_hover`). More than
    :data:`MAX_TRACK_POINTS` rows are thinned to every k-th row of each track (the legend
    says so)."""
    details = details or {}
    tent = (np.zeros(len(tracks), bool) if tracks.tentative is None
            else np.asarray(tracks.tentative, bool))
    segs = _segments(tracks.track_id, tracks.time)
    names, per_row, hover = hover_template(details, word)
    columns = [tracks.track_id, tracks.scan, tracks.time, *(details[n] for n in names)]
    texts = row_text(details, per_row, lead=bool(names)) if per_row else None

    def trace(rows_list: list[np.ndarray], extra: str = "", **kw: Any) -> dict[str, Any]:
        data = [np.column_stack([c[r] for c in columns]) for r in rows_list]
        gaps = np.full((1, len(columns)), np.nan)
        custom = np.concatenate([p for d in data for p in (d, gaps)]) if data else gaps
        if texts is not None:  # the details unknown on some rows (html_hover)
            kw["text"] = [t for r in rows_list for t in (*texts[r].tolist(), "")]
        return {"type": "scatter", "mode": "lines", "legendgroup": "tracks",
                "x": _gapped([tracks.x[r] / scale for r in rows_list]),
                "y": _gapped([tracks.y[r] / scale for r in rows_list]),
                "customdata": custom, "hovertemplate": hover + extra + "<extra></extra>",
                **kw}

    out: list[dict[str, Any]] = []
    if tent.any():  # dotted up to the first confirmed row after the tentative ones
        dotted = [r[: np.flatnonzero(tent[r])[-1] + 2] for r in segs if tent[r].any()]
        dotted, thinned = _thin_rows(dotted, MAX_TRACK_POINTS // 4)
        out.append(trace(dotted, name="tracks before confirmation"
                         + (" (thinned)" if thinned else ""), legendgroup="tentative",
                         line={"color": "#7f7f7f", "width": 1.2, "dash": "dot"}))
    solid = [r[~tent[r]] for r in segs]
    solid = [r for r in solid if len(r)]
    whole = solid
    solid, thinned = _thin_rows(solid, MAX_TRACK_POINTS)
    note = f", every {math.ceil(sum(map(len, whole)) / MAX_TRACK_POINTS)}-th row drawn" \
        if thinned else ""
    if len(solid) > MAX_TRACK_TRACES:
        out.append(trace(solid, name=f"tracks ({len(solid)}{note})",
                         line={"color": "#1f77b4", "width": 1.4}))
        return out
    ends_x: list[float] = []
    ends_y: list[float] = []
    labels: list[str] = []
    colours: list[str] = []
    for j, (r, full) in enumerate(zip(solid, whole, strict=True)):
        tid = int(tracks.track_id[r[0]])
        colour = PALETTE[tid % len(PALETTE)]
        out.append(trace([r], track_labels(full, details),
                         name="tracks" + (f" ({note[2:]})" if note else ""),
                         showlegend=j == 0, line={"color": colour, "width": 1.8}))
        ends_x.append(float(tracks.x[r[-1]] / scale))
        ends_y.append(float(tracks.y[r[-1]] / scale))
        labels.append(str(tid))
        colours.append(colour)
    if labels:  # one text trace for every track's label: one SVG text per track
        out.append({"type": "scatter", "mode": "text", "name": "track labels",
                    "legendgroup": "tracks", "showlegend": False, "hoverinfo": "skip",
                    "x": np.array(ends_x, DRAWN), "y": np.array(ends_y, DRAWN),
                    "text": labels, "textposition": "top right",
                    "textfont": {"color": colours, "size": 10}})
    return out


def site_traces(sites: Sequence[Site], scale: float) -> list[dict[str, Any]]:
    """Radar sites: red triangles, labelled."""
    if not sites:
        return []
    return [{"type": "scatter", "mode": "markers+text", "name": "radar sites",
             "x": [s[0] / scale for s in sites], "y": [s[1] / scale for s in sites],
             "text": [str(s[2]) for s in sites], "textposition": "bottom right",
             "hovertemplate": "%{text}<extra></extra>",
             "marker": {"symbol": "triangle-up", "size": 12, "color": "#d62728",
                        "line": {"color": "black", "width": 1}}}]


def grid_step(span_deg: float) -> float:
    """The first of :data:`GRID_STEPS` giving at most :data:`GRID_LINES` lines over
    ``span_deg`` degrees."""
    for step in GRID_STEPS:
        if span_deg / step <= GRID_LINES:
            return step
    return GRID_STEPS[-1]


def latlon_grid(frame: LocalFrame, box: tuple[float, float, float, float],
                scale: float) -> list[dict[str, Any]]:
    """Lines of constant latitude and longitude over ``box = (x0, x1, y0, y1)`` (local
    frame, m), projected by ``frame`` (WGS-84, azimuthal equidistant): one trace of lines
    and one of their labels. No map tiles: nothing is fetched."""
    x0, x1, y0, y1 = box
    gx, gy = np.meshgrid(np.linspace(x0, x1, 9), np.linspace(y0, y1, 9))
    lat, lon = frame.to_geodetic(gx.ravel(), gy.ravel())
    lat_lo, lat_hi = float(np.min(lat)), float(np.max(lat))
    lon_lo, lon_hi = float(np.min(lon)), float(np.max(lon))
    step = grid_step(max(lat_hi - lat_lo, lon_hi - lon_lo))
    lats = np.arange(math.ceil(lat_lo / step), math.floor(lat_hi / step) + 1) * step
    lons = np.arange(math.ceil(lon_lo / step), math.floor(lon_hi / step) + 1) * step
    fine_lon, fine_lat = np.linspace(lon_lo, lon_hi, 60), np.linspace(lat_lo, lat_hi, 60)
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    lx: list[float] = []
    ly: list[float] = []
    labels: list[str] = []
    for la in lats:
        x, y = frame.to_local(np.full_like(fine_lon, la), fine_lon)
        xs.append(x / scale)
        ys.append(y / scale)
        lx.append(float(x[0] / scale))
        ly.append(float(y[0] / scale))
        labels.append(f"{la:.{_decimals(step)}f}°{'N' if la >= 0 else 'S'}")
    for lo in lons:
        x, y = frame.to_local(fine_lat, np.full_like(fine_lat, lo))
        xs.append(x / scale)
        ys.append(y / scale)
        lx.append(float(x[0] / scale))
        ly.append(float(y[0] / scale))
        labels.append(f"{abs(lo):.{_decimals(step)}f}°{'E' if lo >= 0 else 'W'}")
    style = {"color": "#9aa9c4", "width": 0.8, "dash": "dash"}
    return [
        {"type": "scatter", "mode": "lines", "name": f"lat/lon grid ({step:g}°)",
         "legendgroup": "grid", "x": _gapped(xs), "y": _gapped(ys), "line": style,
         "hoverinfo": "skip"},
        {"type": "scatter", "mode": "text", "name": "lat/lon labels", "legendgroup": "grid",
         "showlegend": False, "x": lx, "y": ly, "text": labels, "hoverinfo": "skip",
         "textposition": "top right", "textfont": {"color": "#5a6f96", "size": 10}},
    ]


def basemap_traces(layers: dict[str, list[np.ndarray]], frame: LocalFrame,
                   box: tuple[float, float, float, float], scale: float
                   ) -> list[dict[str, Any]]:
    """Coastlines and borders (``layers``: name → lines of ``(lat, lon)``,
    :func:`mhtrack.io.basemap.basemap`) over ``box`` and a quarter of its size around
    it, projected by ``frame``; one trace per layer, points beyond that cut out."""
    x0, x1, y0, y1 = box
    m = 0.25 * max(x1 - x0, y1 - y0, 1.0)
    gx, gy = np.meshgrid(np.linspace(x0 - m, x1 + m, 9), np.linspace(y0 - m, y1 + m, 9))
    lat, lon = frame.to_geodetic(gx.ravel(), gy.ravel())
    lat_lo, lat_hi, lon_lo, lon_hi = lat.min(), lat.max(), lon.min(), lon.max()
    out = []
    for name, lines in layers.items():
        xs, ys = [], []
        for line in lines:
            near = ((line[:, 0] >= lat_lo) & (line[:, 0] <= lat_hi)
                    & (line[:, 1] >= lon_lo) & (line[:, 1] <= lon_hi))
            if not near.any():
                continue
            x, y = frame.to_local(line[:, 0], line[:, 1])
            inside = (x >= x0 - m) & (x <= x1 + m) & (y >= y0 - m) & (y <= y1 + m)
            if inside.any():
                xs.append(np.where(inside, x / scale, np.nan))
                ys.append(np.where(inside, y / scale, np.nan))
        if xs:
            out.append({"type": "scatter", "mode": "lines", "name": name,
                        "x": _gapped(xs), "y": _gapped(ys), "hoverinfo": "skip",
                        "line": {"color": "#6b7280", "width": 1.0,
                                 **({"dash": "dot"} if name == "borders" else {})}})
    return out


def _decimals(step: float) -> int:
    return max(0, -math.floor(math.log10(step) + 1e-9)) if step < 1 else 0


def _box(tables: Sequence[Any], sites: Sequence[Site]) -> tuple[float, float, float, float]:
    xs = [np.asarray(t.x, float) for t in tables if t is not None and len(t)]
    ys = [np.asarray(t.y, float) for t in tables if t is not None and len(t)]
    xs += [np.array([s[0] for s in sites], float)] if sites else []
    ys += [np.array([s[1] for s in sites], float)] if sites else []
    if not xs:
        return (-1.0, 1.0, -1.0, 1.0)
    x, y = np.concatenate(xs), np.concatenate(ys)
    x, y = x[np.isfinite(x)], y[np.isfinite(y)]
    return float(x.min()), float(x.max()), float(y.min()), float(y.max())


def scene_figure(plots: PlotTable | None = None, truth: TruthTable | None = None,
                 tracks: TrackTable | None = None, *, sites: Sequence[Site] = (),
                 frame: LocalFrame | None = None, title: str = "",
                 details: dict[str, np.ndarray] | None = None,
                 basemap: dict[str, list[np.ndarray]] | None = None) -> go.Figure:
    """The scene as a :class:`plotly.graph_objects.Figure`: plots, truth, tracks, radar
    ``sites`` and, when ``frame`` is given (a geographic scene), the lat/lon grid.
    Equal axes, kilometres when the scene spans more than 10 km. ``details``: per track
    row, what the hover shows besides id, scan and time (:func:`track_traces`);
    ``basemap``: coastlines and borders of a geographic scene (:func:`basemap_traces`)."""
    import plotly.graph_objects as go

    box = _box((plots, truth, tracks), sites)
    span = max(box[1] - box[0], box[3] - box[2])
    km = math.isfinite(span) and span > KM_ABOVE_M
    scale, unit = (1000.0, "km") if km else (1.0, "m")
    traces: list[dict[str, Any]] = []
    if frame is not None:
        traces += latlon_grid(frame, box, scale)
        if basemap:
            traces += basemap_traces(basemap, frame, box, scale)
    if plots is not None and len(plots):
        traces += plot_traces(plots, scale, word="frame" if plots.timed else "scan")
    if truth is not None and len(truth):
        traces += truth_traces(truth, scale)
    if tracks is not None and len(tracks):
        traces += track_traces(tracks, scale, details,
                               word="frame" if plots is not None and plots.timed else "scan")
    traces += site_traces(sites, scale)
    fig = go.Figure(data=traces)
    fig.update_layout(
        title={"text": title}, height=760, template="plotly_white", dragmode="pan",
        legend={"orientation": "h", "y": -0.08, "x": 0, "yanchor": "top"},
        margin={"l": 60, "r": 20, "t": 50, "b": 60}, hovermode="closest",
        xaxis={"title": {"text": f"x east ({unit})"}, "zeroline": False,
               "constrain": "domain"},
        yaxis={"title": {"text": f"y north ({unit})"}, "scaleanchor": "x", "scaleratio": 1,
               "zeroline": False, "constrain": "domain"},
    )
    return fig
