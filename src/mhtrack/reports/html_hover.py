"""What hovering a track row of the report's scene says (:func:`mhtrack.reports.html_scene.
track_traces`): its id, scan (or frame) and time, then the row's details — speed, heading,
flight level, score, the sensor of the plot it used — and what is constant along the
track (Mode 3/A codes, callsigns, sensors).

**Unknown fields are left out**, not printed as ``NaN`` or ``-1``: a coasting row has no
plot (no sensor, and no flight level unless the tracks file carries the track's own), a
primary-only plot no flight level. A detail known on every row is a number of the
trace's ``customdata`` formatted by the template (compact in the page); a detail unknown
on some rows is written per row, already formatted, into the trace's ``text`` (which a
``lines`` trace does not draw), the empty string where nothing is known.
"""

from __future__ import annotations

import numpy as np

#: The row details in hover order: (name, label before the value, d3/Python format,
#: label after the value).
DETAILS = (("speed", "speed ", ".0f", " m/s"), ("heading", "heading ", ".0f", "°"),
           ("flight_level", "FL ", ".0f", ""), ("score", "score ", ".1f", ""),
           ("sensor", "plot of sensor ", "", ""))
#: Per-track labels: (name, label).
TRACK_LABELS = (("mode_3a", "code"), ("callsign", "callsign"), ("sensor", "sensors"))


def known(name: str, v: np.ndarray) -> np.ndarray:
    """Where detail ``name`` is known: finite numbers; a sensor id ``>= 0`` (``-1``: the
    row used no plot)."""
    if name == "sensor":
        return np.asarray(v) >= 0
    return np.isfinite(np.asarray(v, float))


def hover(details: dict[str, np.ndarray], word: str) -> tuple[list[str], list[str], str]:
    """``(numeric, per_row, template)``: the details known on every row (``customdata``
    from index 3, after id, scan and time), those known on some rows only (formatted by
    :func:`row_text` into ``text``), and the hover template. A detail known on no row is
    left out."""
    numeric, per_row, parts = [], [], []
    for name, before, fmt, after in DETAILS:
        v = details.get(name)
        if v is None:
            continue
        ok = known(name, v)
        if not ok.any():
            continue
        if ok.all():
            spec = f":{fmt}" if fmt else ""
            parts.append(f"{before}%{{customdata[{3 + len(numeric)}]{spec}}}{after}")
            numeric.append(name)
        else:
            per_row.append(name)
    head = f"track %{{customdata[0]}}, {word} %{{customdata[1]}}, t = %{{customdata[2]:.1f}} s"
    body = ", ".join(parts)
    tail = "%{text}" if per_row else ""
    sep = "<br>" if parts or per_row else ""
    return numeric, per_row, head + sep + body + tail


def row_text(details: dict[str, np.ndarray], per_row: list[str], lead: bool) -> np.ndarray:
    """Per row, the known values of the ``per_row`` details as the template would print
    them, joined by ``", "`` (``lead``: each preceded by ``", "``, after the numeric
    details); ``""`` where none is known."""
    n = len(next(iter(details.values()))) if details else 0
    out = np.full(n, "", dtype=object)
    for name, before, fmt, after in DETAILS:
        if name not in per_row:
            continue
        v = np.asarray(details[name])
        ok = known(name, v)
        vals = [f"{before}{x:{fmt}}{after}" for x in (v[ok] if fmt else v[ok].astype(int))]
        cur = out[ok]
        out[ok] = [f"{c}, {s}" if c or lead else s for c, s in zip(cur, vals, strict=True)]
    return out


def track_labels(rows: np.ndarray, details: dict[str, np.ndarray]) -> str:
    """What is constant along a track: its Mode 3/A codes, callsigns and sensors (those
    known; ``""`` and ``-1`` are unknown)."""
    out = []
    for name, label in TRACK_LABELS:
        v = details.get(name)
        if v is None:
            continue
        vals = [x for x in v[rows].tolist() if x not in ("", -1)]
        if vals:
            out.append(f"{label} " + ", ".join(str(x) for x in sorted(set(vals))))
    return "<br>" + ", ".join(out) if out else ""
