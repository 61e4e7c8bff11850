"""What a report shows of a recording without truth: the radars' plot counts and update
rates, the tracks' durations (a table and a histogram of track lengths), and the per-row
details that the scene's hover shows (speed, heading, flight level, Mode 3/A code,
callsign, score, sensors).

Every figure here is computed from the files alone:

* **update interval** of a radar: the median time between consecutive plots of one
  track from that radar (its revisit time as the tracks saw it); the sensors file's
  ``period`` is shown beside it when given;
* **track duration**: ``time[last] − time[first]`` of a track's rows reported at their
  own scan (``tentative`` rows, written later by the history output, not counted);
* **speed** ``√(vx² + vy²)`` and **heading** ``atan2(vx, vy)`` (degrees clockwise from
  the local frame's north) of each track row;
* **flight level, code, callsign**: the tracks file's own columns ``flight_level``,
  ``mode_3a``, ``callsign`` when it has them, else those of the plot each row used
  (plots converted from ASTERIX carry them, docs/file-formats.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from mhtrack.io._frame import FLOAT, TIME, column_names, read_frame
from mhtrack.records import NO_PLOT, PlotTable, TrackTable

if TYPE_CHECKING:
    import plotly.graph_objects as go

#: Optional per-row columns shown on hover: (file column, kind).
DETAIL_COLUMNS = (("flight_level", FLOAT), ("mode_3a", TIME), ("callsign", TIME))
#: Metres per second to knots (1 kn = 1852 m / 3600 s).
KNOTS = 3600.0 / 1852.0


def file_details(path: Path | None) -> dict[str, np.ndarray]:
    """The :data:`DETAIL_COLUMNS` that the file at ``path`` has, one entry per file row
    (flight level as float, NaN when empty; text as ``str``, ``""`` when empty)."""
    if path is None:
        return {}
    names = set(column_names(path))
    kinds = {c: k for c, k in DETAIL_COLUMNS if c in names}
    if not kinds:
        return {}
    f = read_frame(path, kinds, (), "details")
    out: dict[str, np.ndarray] = {}
    for name, kind in kinds.items():
        if kind == FLOAT:
            out[name] = f.floats(name, nullable=True, finite=False)
        else:
            out[name] = np.array(["" if v is None else str(v).strip()
                                  for v in f.table.column(name).to_pylist()], dtype=object)
    return out


def track_details(tracks: TrackTable, tracks_path: Path | None, plots: PlotTable | None,
                  plots_path: Path | None) -> dict[str, np.ndarray]:
    """Per track row: ``speed`` (m/s), ``heading`` (degrees), ``score`` when known, and
    ``flight_level`` / ``mode_3a`` / ``callsign`` from the tracks file or else from the
    plot each row used (module docstring); ``sensor`` of that plot (-1 on a miss)."""
    out: dict[str, np.ndarray] = {
        "speed": np.hypot(tracks.vx, tracks.vy),
        "heading": np.degrees(np.arctan2(tracks.vx, tracks.vy)) % 360.0,
    }
    if tracks.score is not None:
        out["score"] = np.asarray(tracks.score, float)
    own = file_details(tracks_path)
    hit = tracks.plot != NO_PLOT
    if refers_to(tracks, plots):
        rows = np.where(hit, tracks.plot, 0)
        out["sensor"] = np.where(hit, plots.sensor[rows], -1)
        from_plots = file_details(plots_path)
        file_row = rows if plots.file_row is None else plots.file_row[rows]
        for name, v in from_plots.items():
            if name in own or len(v) <= int(file_row.max(initial=0)):
                continue
            missing = np.nan if v.dtype.kind == "f" else ""
            own[name] = np.where(hit, v[file_row], missing)
    if own and all(len(v) == len(tracks) for v in own.values()):
        out.update(own)
    return out


def refers_to(tracks: TrackTable, plots: PlotTable | None) -> bool:
    """Whether every ``plot`` of ``tracks`` is a row of ``plots`` (files of one run)."""
    return (plots is not None and len(plots) > 0
            and int(tracks.plot.max(initial=NO_PLOT)) < len(plots))


def _median_interval(times: np.ndarray, keys: np.ndarray) -> float:
    """Median of ``Δtime`` between consecutive rows of equal ``key`` (rows by key, time)."""
    if len(times) < 2:
        return float("nan")
    order = np.lexsort((times, keys))
    t, k = times[order], keys[order]
    same = k[1:] == k[:-1]
    d = np.diff(t)[same]
    return float(np.median(d)) if len(d) else float("nan")


def radar_rows(plots: PlotTable, tracks: TrackTable | None, periods: dict[int, float]
               ) -> list[list[str]]:
    """Per sensor: plots, time span, plots per second, plots used by tracks, the median
    update interval on tracks (module docstring) and the sensors file's ``period``."""
    used = np.zeros(len(plots), bool)
    sensor_of = np.full(0, -1)
    t_used = np.zeros(0)
    id_used = np.zeros(0, np.int64)
    if tracks is not None and len(tracks) and refers_to(tracks, plots):
        online = tracks.online()
        hit = online.plot != NO_PLOT
        used[online.plot[hit]] = True
        sensor_of = plots.sensor[online.plot[hit]]
        t_used, id_used = plots.time[online.plot[hit]], online.track_id[hit]
    rows = []
    for s in np.unique(plots.sensor).tolist():
        mine = plots.sensor == s
        t = plots.time[mine]
        span = float(t.max() - t.min()) if len(t) else 0.0
        k = sensor_of == s
        interval = _median_interval(t_used[k], id_used[k])
        period = periods.get(int(s))
        rows.append([str(s), str(int(mine.sum())), f"{t.min():.1f} – {t.max():.1f}",
                     f"{mine.sum() / span:.3g}" if span > 0 else "–",
                     f"{int(used[mine].sum())} ({100 * used[mine].mean():.0f} %)",
                     f"{interval:.3g}" if np.isfinite(interval) else "–",
                     "–" if period is None else f"{period:g}"])
    return rows


RADAR_HEADER = ("sensor", "plots", "time span (s)", "plots per second",
                "plots used by tracks", "median update interval on tracks (s)",
                "period in the sensors file (s)")


def durations(tracks: TrackTable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(track ids, durations in s, rows per track)`` of the rows reported online."""
    t = tracks.online()
    if not len(t):
        return np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.int64)
    ids, inv, counts = np.unique(t.track_id, return_inverse=True, return_counts=True)
    first = np.full(len(ids), np.inf)
    last = np.full(len(ids), -np.inf)
    np.minimum.at(first, inv, t.time)
    np.maximum.at(last, inv, t.time)
    return ids, last - first, counts


def track_rows(tracks: TrackTable, details: dict[str, np.ndarray]) -> list[tuple[str, str]]:
    """The tracks' summary: counts, durations (min / median / mean / max), rows per
    track, median speed."""
    ids, d, counts = durations(tracks)
    rows = [("track ids (reported at their own scan)", str(len(ids))),
            ("track rows", str(len(tracks)))]
    if tracks.tentative is not None:
        rows.append(("  of which reported after confirmation (tentative)",
                     str(int(np.count_nonzero(tracks.tentative)))))
    if len(ids):
        rows += [("track duration min / median / mean / max (s)",
                  " / ".join(f"{v:.1f}" for v in (d.min(), np.median(d), d.mean(), d.max()))),
                 ("total track time (s)", f"{d.sum():.0f}"),
                 ("rows per track median / max", f"{np.median(counts):g} / {counts.max()}")]
        speed = details["speed"][tracks.tentative == 0] if tracks.tentative is not None \
            else details["speed"]
        if len(speed):
            rows.append(("speed median (m/s)", f"{np.median(speed):.1f}"))
    return rows


def lengths_figure(tracks: TrackTable, title: str = "") -> go.Figure:
    """A histogram of track durations (s), one bar per bin of numpy's ``auto`` rule."""
    import plotly.graph_objects as go

    _, d, _ = durations(tracks)
    counts, edges = np.histogram(d, bins="auto") if len(d) else (np.zeros(0), np.zeros(1))
    centres = (edges[:-1] + edges[1:]) / 2
    fig = go.Figure(data=[{"type": "bar", "x": centres, "y": counts,
                           "width": np.diff(edges), "name": "tracks",
                           "marker": {"color": "#1f77b4"},
                           "customdata": np.column_stack([edges[:-1], edges[1:]])
                           if len(d) else None,
                           "hovertemplate": "%{y} tracks lasting %{customdata[0]:.0f}–"
                                            "%{customdata[1]:.0f} s<extra></extra>"}])
    fig.update_layout(title={"text": title}, height=340, template="plotly_white",
                      bargap=0.02, margin={"l": 60, "r": 20, "t": 40, "b": 50},
                      xaxis={"title": {"text": "track duration (s)"}},
                      yaxis={"title": {"text": "tracks"}})
    return fig


def sensor_rows(sensor_set: Any) -> list[tuple[str, str]]:
    """The sensors file, one row per radar."""
    rows = []
    if sensor_set is None:
        return rows
    if sensor_set.origin is not None:
        rows.append(("origin (lat, lon)", f"{sensor_set.origin[0]:g}, {sensor_set.origin[1]:g}"))
    for s in sensor_set.sensors:
        parts = [s.kind]
        if s.lat is not None:
            parts.append(f"site {s.lat:g}, {s.lon:g}")
        for key, label, unit in (("pd", "P_D", ""), ("period", "period", " s"),
                                 ("max_range", "range", " m"),
                                 ("sigma_range", "σr", " m"),
                                 ("sigma_bearing_deg", "σθ", "°"), ("sigma", "σ", " m")):
            v = getattr(s, key, None)
            if v is not None:
                parts.append(f"{label} {v:g}{unit}")
        rows.append((f"sensor {s.id}", ", ".join(parts)))
    return rows


def periods_of(sensor_set: Any) -> dict[int, float]:
    """``{sensor id: period}`` of the sensors with one."""
    if sensor_set is None:
        return {}
    return {int(s.id): float(s.period) for s in sensor_set.sensors
            if getattr(s, "period", None) is not None}


def joined(values: Sequence[Any]) -> str:
    """``1, 2, 3`` of the distinct values, sorted."""
    return ", ".join(str(v) for v in sorted(set(values)))
