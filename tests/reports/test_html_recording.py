"""The report of a recording without truth (issue 31): title, radars' plot counts and
update intervals, track durations and their histogram, the hover's details, thinning of
big scenes, Plotly's JavaScript beside the page; and the units and words the run page
shares with ``evaluate``."""

from __future__ import annotations

import csv
import re
import shutil
from collections import Counter

import numpy as np
import pytest

pytest.importorskip("plotly", reason="the HTML report needs the optional extra [report]")

from mhtrack.io import read_tracks
from mhtrack.records import TrackTable
from mhtrack.reports import html_scene
from mhtrack.reports.html_metrics import curves_figure, metric_rows
from mhtrack.reports.html_page import plotlyjs_name
from mhtrack.reports.html_recording import durations, track_details
from mhtrack.reports.html_report import report_page, write_html_report


def _cells(page, heading):
    """Rows of the first table after ``<h2>heading</h2>``, as lists of cell texts."""
    part = page.split(f"<h2>{heading}</h2>", 1)[1].split("</table>", 1)[0]
    return [re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", r) for r in part.split("<tr>")[1:]]


def test_recording_page_has_every_section(recording_dir):
    page = report_page(recording_dir).render()
    with open(recording_dir / "plots.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    with open(recording_dir / "tracks.csv", newline="") as fh:
        track_rows = list(csv.DictReader(fh))
    ids = {r["track_id"] for r in track_rows if r["tentative"] == "0"}
    title = re.search(r"<h1>(.*?)</h1>", page)[1]
    assert title == (f"mhtrack report: recording, {len(ids)} tracks, {len(rows)} plots from "
                     "3 radars")
    for h in ("Scene", "Radars", "Tracks", "Parameters and caps"):
        assert f"<h2>{h}</h2>" in page
    assert "Metrics</h2>" not in page and "No metrics" not in page
    # per radar: the plot count of the file, and the median interval between a track's
    # plots of one radar = that radar's rotation period (4, 10, 12 s in sensors.toml)
    radars = _cells(page, "Radars")[1:]
    count = Counter(r["sensor"] for r in rows)
    assert [(r[0], r[1]) for r in radars] == [(s, str(count[s])) for s in ("1", "2", "3")]
    assert [float(r[5]) for r in radars] == pytest.approx([4.0, 10.0, 12.0], rel=0.02)
    assert [r[6] for r in radars] == ["4", "10", "12"]
    # durations: hand-computed from the file's online rows
    first, last = {}, {}
    for r in track_rows:
        if r["tentative"] == "0":
            t = float(r["time"])
            first[r["track_id"]] = min(first.get(r["track_id"], t), t)
            last[r["track_id"]] = max(last.get(r["track_id"], t), t)
    d = np.array([last[k] - first[k] for k in first])
    table = dict((r[0], r[1]) for r in _cells(page, "Tracks")[1:])
    assert table["track ids (reported at their own scan)"] == str(len(ids))
    assert table["track duration min / median / mean / max (s)"] == " / ".join(
        f"{v:.1f}" for v in (d.min(), np.median(d), d.mean(), d.max()))
    assert 'id="fig-lengths"' in page


def test_histogram_counts_every_track_once(recording_dir):
    tracks = read_tracks(recording_dir / "tracks.csv")
    fig = __import__("mhtrack.reports.html_recording", fromlist=["x"]).lengths_figure(tracks)
    ids, d, _ = durations(tracks)
    assert int(np.sum(fig.data[0].y)) == len(ids) == len(d)


def _details(tmp_path, plot_rows: str):
    """A hand-made track 4 (due south at 10 m/s for two scans, then east at 5 m/s,
    coasting) over the plots ``plot_rows`` (scan,time,sensor,x,y,flight_level,mode_3a),
    both written as files: ``(tracks, track_details)``."""
    (tmp_path / "plots.csv").write_text(
        "scan,time,sensor,x,y,flight_level,mode_3a\n" + plot_rows)
    (tmp_path / "tracks.csv").write_text(
        "scan,time,track_id,x,y,vx,vy,plot,score\n"
        "0,0.0,4,0,0,0,-10,0,1.5\n1,1.0,4,0,-10,0,-10,1,2.5\n2,2.0,4,5,-10,5,0,,3.5\n")
    from mhtrack.io import read_plots

    plots = read_plots(tmp_path / "plots.csv")
    tracks = read_tracks(tmp_path / "tracks.csv")
    return tracks, track_details(tracks, tmp_path / "tracks.csv", plots,
                                 tmp_path / "plots.csv")


def test_hover_details_speed_heading_and_plot_fields(tmp_path):
    """Speed and heading of a hand-made track (due south at 10 m/s: 180°; east at 5 m/s:
    90°); flight level and code from the plot each row used."""
    _, d = _details(tmp_path, "0,0.0,7,0,0,350,7000\n1,1.0,7,0,-10,351.25,7000\n"
                    "2,2.0,7,5,-10,,\n")
    assert d["speed"].tolist() == [10.0, 10.0, 5.0]
    assert d["heading"].tolist() == [180.0, 180.0, 90.0]
    assert d["score"].tolist() == [1.5, 2.5, 3.5]
    assert d["sensor"].tolist() == [7, 7, -1]
    assert d["flight_level"][:2].tolist() == [350.0, 351.25] and np.isnan(d["flight_level"][2])
    assert d["mode_3a"].tolist() == ["7000", "7000", ""]
    page = report_page(tmp_path).render()
    assert "speed %{customdata[3]:.0f} m\\u002fs" in page and "%{text}" in page
    assert "code 7000" in page and "sensors 7" in page


def _hovered(trace) -> list[str]:
    """The hover label of each drawn row of a track trace, the template filled in as
    Plotly does for the specifiers it uses here (``%{customdata[i]:.Nf}``,
    ``%{customdata[i]}``, ``%{text}``); the gap rows between tracks left out."""
    out = []
    for i, row in enumerate(trace["customdata"]):
        if np.isnan(row[0]):
            continue

        def field(m, row=row, i=i):
            if m[1] == "text":
                return trace["text"][i]
            v = row[int(m[2])]
            return format(v, m[3][1:]) if m[3] else str(int(v))
        label = re.sub(r"%\{(text|customdata\[(\d+)\])(:[^}]*)?\}", field,
                       trace["hovertemplate"])
        out.append(label.removesuffix("<extra></extra>"))
    return out


def test_hover_leaves_out_what_a_row_does_not_know(tmp_path):
    """A coasting row (no plot) and a primary-only plot (no flight level): their hover
    names no flight level and no sensor — no ``NaN``, no ``-1`` — while the rows that
    know them show them; hand-written labels."""
    tracks, d = _details(tmp_path, "0,0.0,7,0,0,350,7000\n1,1.0,2,0,-10,,\n")
    [trace, _labels] = html_scene.track_traces(tracks, 1.0, d)
    head = "track 4, scan {}, t = {}.0 s<br>speed {} m/s, heading {}°, score {}"
    assert _hovered(trace) == [
        head.format(0, 0, 10, 180, 1.5) + ", FL 350, plot of sensor 7<br>code 7000, "
        "sensors 2, 7",
        head.format(1, 1, 10, 180, 2.5) + ", plot of sensor 2<br>code 7000, sensors 2, 7",
        head.format(2, 2, 5, 90, 3.5) + "<br>code 7000, sensors 2, 7"]
    page = report_page(tmp_path).render()
    assert "NaN" not in "".join(_hovered(trace)) and "sensor -1" not in page


def test_big_scenes_are_thinned_and_the_page_says_so(recording_dir, monkeypatch, tmp_path):
    monkeypatch.setattr(html_scene, "MAX_TRACK_POINTS", 100)
    monkeypatch.setattr(html_scene, "MAX_PLOTS", 300)
    page = report_page(recording_dir).render()
    assert "Thinned for drawing" in page
    tracks = read_tracks(recording_dir / "tracks.csv")
    traces = html_scene.track_traces(tracks, 1000.0)
    drawn = sum(int(np.count_nonzero(~np.isnan(np.asarray(t["x"], float)))) for t in traces)
    assert drawn < len(tracks) and any("th row drawn" in t.get("name", "") for t in traces)
    # every track keeps its last row (its end is where the label goes)
    solid = [t for t in traces if t.get("legendgroup") == "tracks" and t["mode"] != "text"]
    ends = {int(t["customdata"][-2][0]): float(t["x"][-2]) for t in solid}
    online = tracks.online()
    for tid, x in ends.items():
        rows = np.flatnonzero(online.track_id == tid)
        assert x == pytest.approx(online.x[rows[np.argmax(online.time[rows])]] / 1000.0,
                                  rel=1e-6)


def test_plotlyjs_beside_the_page(recording_dir, tmp_path):
    from plotly.offline import get_plotlyjs

    d = tmp_path / "r"
    shutil.copytree(recording_dir, d)
    page = write_html_report(d, plotlyjs="file")
    text = page.read_text()
    assert f'<script type="text/javascript" src="{plotlyjs_name()}"></script>' in text
    assert (d / plotlyjs_name()).read_text() == get_plotlyjs()
    inline = report_page(d).render()
    assert len(inline) - len(text) > len(get_plotlyjs()) - 1000


def test_track_life_in_seconds_and_hover_word_follows_the_axis():
    rows = dict(metric_rows({"l_min": 12.0, "l_avg": 30.5, "l_max": 60.0,
                             "delay_mean": 2.0}))
    assert rows["Lmin (track life)"] == "12 s" and rows["Lavg"] == "30.5 s"
    assert rows["Lmax"] == "60 s" and rows["confirmation delay mean (scans)"] == "2"
    curves = {"t": {"scans": [0, 1], "ospa": [1.0, 2.0], "cardinality": [1, 1],
                    "cardinality_true": [1, 1]}}
    fig = curves_figure(curves, x_title="truth time index")
    hovers = [t.hovertemplate for t in fig.data if t.hovertemplate]
    assert hovers and all("at truth time index %{x}" in h for h in hovers)
    assert fig.layout.xaxis2.title.text == "truth time index"


def test_tracks_without_plots_still_report(tmp_path):
    t = TrackTable(scan=np.array([0, 1]), time=np.array([0.0, 1.0]),
                   track_id=np.array([1, 1]), x=np.zeros(2), y=np.zeros(2), vx=np.ones(2),
                   vy=np.zeros(2), plot=np.array([-1, -1]))
    from mhtrack.io import write_tracks

    write_tracks(t, tmp_path / "tracks.csv")
    page = report_page(tmp_path).render()
    assert "<h2>Tracks</h2>" in page and "<h2>Radars</h2>" not in page
