"""The HTML report in a real browser: headless Chromium (Debian's ``chromium`` package,
installed by .ci/run) opens the page from disk over the DevTools protocol (conftest.py),
every figure draws all its traces as SVG, the console shows no error, nothing is fetched
from the network, and a screenshot of the whole page is saved in the test's tmp folder.
Skipped, with the reason, where no Chromium is installed."""

from __future__ import annotations

import csv
import json
import re
import shutil
import struct

import pytest

pytest.importorskip("plotly", reason="the HTML report needs the optional extra [report]")

from mhtrack.reports import montecarlo
from mhtrack.reports.html_report import REPORT_FILE, write_html_report


def _png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return struct.unpack(">II", data[16:24])


def _clean(check):
    assert check.errors == [], check.errors
    assert check.requests == [], check.requests
    for f in check.figures:
        assert f["svg"] > 0, f
        assert f["drawn"] == f["given"], f
    width, height = _png_size(check.screenshot)
    assert width == 1400 and height > 1000


def test_run_report_renders(run_dir, open_in_browser, track_ids):
    check = open_in_browser(run_dir / REPORT_FILE)
    _clean(check)
    got = {f["id"]: f["drawn"] for f in check.figures}
    # scene: clutter, target plots, truth line, births, deaths, the tracks and their
    # labels; curves: OSPA, cardinality, the true number of targets (no OSPA(2) here)
    confirmed, tentative = track_ids(run_dir / "tracks.csv")
    scene = 2 + 3 + len(confirmed) + 1 + tentative
    m = json.loads((run_dir / "metrics.json").read_text())
    curves = 3 + bool([v for v in m.get("ospa2") or [] if v is not None])
    assert got == {"fig-scene": scene, "fig-curves": curves, "fig-lengths": 1}
    points = {f["id"]: f["points"] for f in check.figures}
    with open(run_dir / "plots.csv", newline="") as fh:
        n_plots = sum(1 for _ in csv.DictReader(fh))
    with open(run_dir / "truth.csv", newline="") as fh:
        n_targets = len({r["target_id"] for r in csv.DictReader(fh)})
    assert points["fig-scene"] == n_plots + 2 * n_targets  # markers: plots, births, deaths


def test_geographic_report_renders(geo_dir, open_in_browser, tmp_path, track_ids):
    page = write_html_report(geo_dir, tmp_path / "geo.html")
    check = open_in_browser(page)
    _clean(check)
    # scene: lat/lon grid and its labels, clutter, target plots, truth (3), tracks and
    # their labels, sites
    confirmed, tentative = track_ids(geo_dir / "tracks.csv")
    scene = 2 + 2 + 3 + len(confirmed) + 1 + tentative + 1
    assert {f["id"]: f["drawn"] for f in check.figures}["fig-scene"] == scene


def test_geographic_report_with_coastlines_renders(geo_dir, open_in_browser, tmp_path,
                                                  track_ids, cached_coastlines):
    """The tiny Natural Earth fixture from the cache: two more traces drawn, coastlines
    and borders, nothing fetched."""
    page = write_html_report(geo_dir, tmp_path / "geo-coast.html", coastlines=True)
    check = open_in_browser(page)
    _clean(check)
    confirmed, tentative = track_ids(geo_dir / "tracks.csv")
    scene = 2 + 2 + 2 + 3 + len(confirmed) + 1 + tentative + 1
    assert {f["id"]: f["drawn"] for f in check.figures}["fig-scene"] == scene


def test_study_report_renders(study_dir, open_in_browser, tmp_path, monkeypatch):
    monkeypatch.delattr(montecarlo, "paired_comparisons", raising=False)
    d = tmp_path / "mc"
    shutil.copytree(study_dir, d)
    paired = [{"metric": m, "a": "mht-agmm", "b": "mht-gmm", "higher_better": hb, "n": 3,
               "mean_diff": 1.0, "ci_low": 0.5, "ci_high": 1.5, "verdict": "worse"}
              for m, hb in (("ospa_mean", False), ("rcc", True))]
    (d / "results.json").write_text(json.dumps({"paired": paired}))
    check = open_in_browser(write_html_report(d))
    _clean(check)
    # curves: per tracker and panel a band and a mean (2 × 2 × 2), the true cardinality;
    # paired: one trace per metric
    assert {f["id"]: f["drawn"] for f in check.figures} == {"fig-curves": 9, "fig-paired": 2}


def test_the_check_sees_errors_and_network(open_in_browser, tmp_path):
    """The browser check can fail: a page that throws and fetches from another host."""
    page = tmp_path / "bad.html"
    page.write_text('<!DOCTYPE html><html><body><div class="plotly-graph-div"></div>'
                    '<img src="http://127.0.0.1:9/x.png">'
                    "<script>console.error('broken'); undefinedFunction();</script>"
                    "</body></html>")
    check = open_in_browser(page)
    assert any("undefinedFunction" in e for e in check.errors), check.errors
    assert any("broken" in e for e in check.errors), check.errors
    assert check.requests == ["http://127.0.0.1:9/x.png"]
    assert check.figures == [{"id": "", "given": 0, "drawn": 0, "svg": 0, "points": 0}]


def test_recording_report_renders(recording_dir, open_in_browser, tmp_path, track_ids):
    """Plots, sensors and tracks, no truth: the scene and the histogram of track lengths
    draw; the page has the radars' and the tracks' tables."""
    page = write_html_report(recording_dir, tmp_path / "recording.html")
    check = open_in_browser(page)
    _clean(check)
    confirmed, tentative = track_ids(recording_dir / "tracks.csv")
    # scene: lat/lon grid and its labels, plots (clutter and target plots when the file
    # has an origin column), tracks and their labels, sites; lengths: one bar trace
    with open(recording_dir / "plots.csv", newline="") as fh:
        kinds = 2 if "origin" in next(csv.reader(fh)) else 1
    scene = 2 + kinds + len(confirmed) + 1 + tentative + 1
    assert {f["id"]: f["drawn"] for f in check.figures} == {"fig-scene": scene,
                                                            "fig-lengths": 1}
    text = page.read_text()
    for heading in ("Scene", "Radars", "Tracks", "Parameters and caps"):
        assert f"<h2>{heading}</h2>" in text


#: Hover, in the first per-track trace whose hover names a code (Plotly's own hover, as a
#: pointer would), the middle one of its rows with a plot, then the middle one of its
#: rows without (coasting; "none" if it has none); return the two labels' texts.
HOVER_JS = """(async () => {
  const gd = document.getElementById('fig-scene');
  const i = gd.data.findIndex(t => t.legendgroup === 'tracks' && t.mode === 'lines'
                                   && (t.hovertemplate || '').includes('code'));
  if (i < 0) return ['no track trace with a code', ''];
  const cd = gd._fullData[i].customdata, text = gd.data[i].text;
  const rows = Array.from({length: cd.length}, (_, p) => p).filter(p => !isNaN(cd[p][0]));
  const label = async pick => {
    if (!pick.length) return 'none';
    Plotly.Fx.unhover(gd);
    await new Promise(r => setTimeout(r, 200));  // Plotly drops hovers 50 ms apart
    Plotly.Fx.hover(gd, [{curveNumber: i, pointNumber: pick[Math.floor(pick.length / 2)]}]);
    return Array.from(gd.querySelectorAll('g.hoverlayer g.hovertext'))
      .map(g => g.textContent).join(' | ');
  };
  const hit = p => text ? text[p].includes('plot of sensor') : true;
  return [await label(rows.filter(hit)), await label(rows.filter(p => !hit(p)))];
})()"""


def test_recording_hover_and_tables(recording_dir, open_in_browser, tmp_path):
    """A recording whose plots carry a flight level and a Mode 3/A code (as converted
    from ASTERIX): hovering a track's row with a plot in the browser shows its id, speed,
    heading, flight level, score, the plot's sensor, its code and sensors; a coasting row
    (no plot) names neither flight level nor sensor (no NaN, no -1); the radars table
    has a row
    per radar with its plots counted, the tracks table the durations."""
    d = tmp_path / "rec-fl"
    d.mkdir()
    for name in ("sensors.toml", "tracks.csv"):
        shutil.copy(recording_dir / name, d / name)
    with open(recording_dir / "plots.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    with open(d / "plots.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, [*rows[0], "flight_level", "mode_3a"])
        w.writeheader()
        for r in rows:  # FL 310, 320, 330 by radar; code 7000 on the target plots
            w.writerow({**r, "flight_level": str(300 + 10 * int(r["sensor"])),
                        "mode_3a": "7000" if r["origin"] != "-1" else ""})
    page = write_html_report(d, d / "report.html")
    check = open_in_browser(page, probe=HOVER_JS)
    _clean(check)
    hover, coasting = check.probe
    assert re.search(r"^track \d+, frame \d+, t = [\d.]+ s", hover), hover
    for part in (r"speed \d+ m/s", r"heading \d+°", r"FL 3[123]0", r"score -?[\d.]+",
                 r"plot of sensor [123]", r"code 7000", r"sensors [123](, [123])*"):
        assert re.search(part, hover), (part, hover)
    assert coasting != "none", "the fixture's tracks coast somewhere"
    assert re.search(r"^track \d+, frame \d+, t = [\d.]+ s.*speed \d+ m/s", coasting)
    for unknown in ("NaN", "sensor -1", "FL", "plot of sensor"):
        assert unknown not in coasting, (unknown, coasting)
    text = page.read_text()
    radars = text[text.index("<h2>Radars</h2>"):text.index("<h2>Tracks</h2>")]
    counts = {s: sum(r["sensor"] == s for r in rows) for s in {r["sensor"] for r in rows}}
    for s, n in counts.items():
        assert f"<tr><td>{s}</td><td class=\"num\">{n}</td>" in radars
    assert "track duration min / median / mean / max (s)" in text


@pytest.fixture(scope="module")
def twenty_minutes(tmp_path_factory):
    """``simulate opensky-radars`` for 20 minutes (120 scans of 10 s), ``track``, and the
    truth removed: a recording of three radars."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    d = tmp_path_factory.mktemp("rec20")
    for args in (["simulate", "opensky-radars", "--seed", "1", "--scans", "120", "--out",
                  str(d)],
                 ["track", str(d / "plots.csv"), "--out", str(d / "tracks.csv"), "--quiet"]):
        r = CliRunner().invoke(cli, args)
        assert r.exit_code == 0, r.output
    for name in ("truth.csv", "scenario.toml"):
        (d / name).unlink()
    return d


@pytest.mark.slow
@pytest.mark.parametrize("plotlyjs", ["inline", "file"])
def test_twenty_minute_report_size_and_load_time(plotlyjs, twenty_minutes, open_in_browser,
                                                 tmp_path, record_property):
    """A 20-minute three-radar recording's report renders cleanly and says it was thinned
    for drawing; its size, the time until every figure is drawn (the browser's own
    clock) and Chromium's CPU time meanwhile are logged, not asserted."""
    d = tmp_path / "rec"
    shutil.copytree(twenty_minutes, d)
    page = write_html_report(d, d / f"report-{plotlyjs}.html", plotlyjs=plotlyjs)
    check = open_in_browser(page)
    _clean(check)
    js = sum(p.stat().st_size for p in d.glob("plotly-*.min.js"))
    assert (js > 0) == (plotlyjs == "file")
    text = page.read_text()
    assert "Thinned for drawing: at most 5000 plots of each kind" in text
    assert re.search(r'"name":"(clutter|target plots) \(5000 of \d+ drawn\)"', text)
    record_property("measured", (
        f"20-minute 3-radar report (plotly.js {plotlyjs}): page "
        f"{page.stat().st_size / 1e6:.2f} MB" + (f" + plotly.js {js / 1e6:.2f} MB" if js
                                                  else "")
        + f", drawn {check.load_ms / 1000:.2f} s after navigation, Chromium CPU "
        f"{check.cpu_s:.2f} s (headless Chromium)"))
