"""``mhtrack report`` / ``run --report`` without a browser: the page is self-contained and
deterministic, shows the run's own numbers, draws the lat/lon grid where geographiclib
puts it, adds the OSPA(2) panel when evaluated, and the study's paired comparisons when
some exist. The browser checks are in test_html_browser.py."""

from __future__ import annotations

import json
import math
import re
import shutil
import sys

import numpy as np
import pytest

pytest.importorskip("plotly", reason="the HTML report needs the optional extra [report]")

from geodesic_reference import WGS84

from mhtrack.models.geodesy import LocalFrame
from mhtrack.reports import montecarlo
from mhtrack.reports.html_metrics import curves_figure
from mhtrack.reports.html_report import REPORT_FILE, report_page, write_html_report
from mhtrack.reports.html_scene import grid_step, latlon_grid
from mhtrack.reports.html_study import paired_figure

#: Anything the page would fetch: a src/href to another host, a CSS import or url().
NETWORK = re.compile(r"""(?:src|href)\s*=\s*["']?\s*(?:https?:)?//|@import|url\(\s*["']?https?:""",
                     re.IGNORECASE)


def invoke(*args):
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    r = CliRunner().invoke(cli, list(args))
    return r.exit_code, r.stdout, r.stderr


def _json(text: str) -> str:
    """``text`` as Plotly writes it in a figure's JSON (``/`` escaped as ``\\u002f``)."""
    return text.replace("/", "\\u002f")


def _tags(page: str) -> list[str]:
    """The HTML tags of the page outside the inlined scripts."""
    outside = re.sub(r"<script[^>]*>.*?</script>", "<script>", page, flags=re.DOTALL)
    return re.findall(r"<[a-zA-Z][^>]*>", outside)


def test_run_report_is_self_contained(run_dir):
    page = (run_dir / REPORT_FILE).read_text(encoding="utf-8")
    tags = _tags(page)
    assert not [t for t in tags if NETWORK.search(t)]
    assert not [t for t in tags if t.startswith(("<link", "<iframe", "<img"))]
    scripts = re.findall(r"<script([^>]*)>", page)
    assert scripts and not [s for s in scripts if "src" in s]
    assert page.count("Plotly.newPlot(") == 3  # the scene, the curves, the track lengths
    assert "plotly.js v" in page[:5_000_000]  # the library itself, inlined
    assert page.count("plotly.js v") == 1  # once, whatever the number of figures
    for heading in ("Scene", "Metrics over time", "Metrics", "Parameters and caps"):
        assert f"<h2>{heading}</h2>" in page


def test_report_is_deterministic(run_dir, tmp_path):
    a = write_html_report(run_dir, tmp_path / "a.html").read_bytes()
    b = write_html_report(run_dir, tmp_path / "b.html").read_bytes()
    assert a == b == (run_dir / REPORT_FILE).read_bytes()


def test_metrics_table_shows_metrics_json(run_dir):
    page = (run_dir / REPORT_FILE).read_text(encoding="utf-8")
    m = json.loads((run_dir / "metrics.json").read_text())
    for key, unit in (("ospa_mean", " m"), ("gospa_mean", " m"), ("mota", ""),
                      ("rcc", ""), ("l_avg", " s")):  # track life in s, as evaluate
        assert f'<td class="num">{m[key]:.4g}{unit}</td>' in page, key
    assert f"<td>{m['n_false']}</td>" in page or f'<td class="num">{m["n_false"]}</td>' in page
    assert "<td>tracker</td><td>mht-agmm</td>" in page
    assert "<td>seed</td><td>1</td>" in page


def test_scene_traces_follow_the_files(run_dir, track_ids):
    page = report_page(run_dir)
    confirmed, tentative = track_ids(run_dir / "tracks.csv")
    html = page.render()
    # one trace per id, and one of their labels (the ids, at the tracks' ends)
    assert html.count('"legendgroup":"tracks"') == len(confirmed) + 1
    from mhtrack.io import read_tracks
    from mhtrack.reports.html_scene import track_traces

    traces = track_traces(read_tracks(run_dir / "tracks.csv"), 1.0)
    labels = [t for t in traces if t["name"] == "track labels"]
    assert len(labels) == 1 and sorted(labels[0]["text"]) == sorted(confirmed)
    assert ('"name":"tracks before confirmation"' in html) == tentative
    assert '"name":"clutter"' in html and '"name":"target plots"' in html
    assert '"name":"truth"' in html
    assert _json("lat/lon grid") not in html and '"radar sites"' not in html  # flat


@pytest.mark.parametrize(("span", "step"), [(12.0, 2.0), (0.3, 0.05), (8.0, 1.0),
                                             (0.05, 0.01), (500.0, 30.0)])
def test_grid_step(span, step):
    assert grid_step(span) == step


def test_grid_lines_are_parallels_and_meridians():
    """Each grid line, carried back to the ellipsoid by geographiclib's geodesic from the
    frame's origin (azimuthal equidistant: distance and azimuth kept), keeps one
    latitude or one longitude, a multiple of the grid step."""
    frame = LocalFrame(52.067, -1.454)
    lines, labels = latlon_grid(frame, (-280e3, 240e3, -250e3, 300e3), 1000.0)
    step = float(re.search(r"\(([\d.]+)°\)", lines["name"]).group(1))
    x, y = np.asarray(lines["x"], float) * 1e3, np.asarray(lines["y"], float) * 1e3
    cuts = np.flatnonzero(np.isnan(x))
    starts = np.r_[0, cuts[:-1] + 1]
    n_par = n_mer = 0
    for s, e in zip(starts, cuts, strict=True):
        lat, lon = [], []
        for xi, yi in zip(x[s:e], y[s:e], strict=True):
            g = WGS84.Direct(52.067, -1.454, math.degrees(math.atan2(xi, yi)),
                                      math.hypot(xi, yi))
            lat.append(g["lat2"])
            lon.append(g["lon2"])
        if np.ptp(lat) < 1e-6:
            n_par += 1
            assert abs(lat[0] / step - round(lat[0] / step)) < 1e-6
        else:
            assert np.ptp(lon) < 1e-6
            n_mer += 1
            assert abs(lon[0] / step - round(lon[0] / step)) < 1e-6
    assert n_par >= 2 and n_mer >= 2
    assert len(labels["text"]) == n_par + n_mer
    assert "52°N" in labels["text"] and "2°W" in labels["text"]


def test_geographic_report_without_metrics_json(geo_dir):
    page = report_page(geo_dir).render()
    assert "metrics computed for this page with evaluate&#x27;s defaults" in page
    assert _json("lat/lon grid") in page and '"radar 1"' in page
    code, out, err = invoke("evaluate", str(geo_dir / "tracks.csv"),
                            str(geo_dir / "truth.csv"), "--json")
    assert code == 0, err
    m = json.loads(out)
    assert f'<td class="num">{m["ospa_mean"]:.4g} m</td>' in page
    assert f'<td class="num">{m["mota"]:.4g}</td>' in page


def _curves(ospa2=None):
    c = {"scans": [0, 1, 2], "ospa": [1.0, 2.0, 3.0], "cardinality": [1, 2, 2],
         "cardinality_true": [2, 2, 2]}
    if ospa2 is not None:
        c["ospa2"] = ospa2
    return {"t": c}


@pytest.mark.parametrize(("ospa2", "panels"), [(None, 2), ([], 2), ([None, None, None], 2),
                                               ([5.0, None, 4.0], 3)])
def test_ospa2_panel_only_when_evaluated(ospa2, panels):
    fig = curves_figure(_curves(ospa2), ospa2_window=10)
    axes = [k for k in fig.layout.to_plotly_json() if k.startswith("yaxis")]
    assert len(axes) == panels
    titles = [a.text for a in fig.layout.annotations]
    assert any("OSPA(2)" in t for t in titles) == (panels == 3)
    assert len(fig.data) == panels + 1  # one curve per panel, the true cardinality


PAIRED = [{"metric": "ospa_mean", "a": "mht-agmm", "b": "mht-gmm", "higher_better": False,
           "n": 3, "mean_diff": -4.0, "ci_low": -7.5, "ci_high": -0.5, "verdict": "better",
           "sentence": "mht-agmm is better than mht-gmm"},
          {"metric": "rcc", "a": "mht-agmm", "b": "mht-gmm", "higher_better": True, "n": 3,
           "mean_diff": 0.01, "ci_low": None, "ci_high": None,
           "verdict": "no detectable difference", "sentence": ""}]


def test_paired_figure_intervals():
    fig = paired_figure(PAIRED)
    assert len(fig.data) == 2
    ex = fig.data[0].error_x
    assert fig.data[0].x == (-4.0,)
    assert ex.arrayminus == (3.5,) and ex.array == (3.5,)  # mean − low, high − mean
    assert fig.data[0].marker.color == ("#2ca02c",)
    assert fig.data[1].error_x.array == (0.0,)  # no interval: no bar


def test_study_without_paired_shows_the_tracker_table(study_dir, tmp_path, monkeypatch):
    import pyarrow.parquet as pq  # a runtime dependency (pandas is not: the tour has none)

    monkeypatch.delattr(montecarlo, "paired_comparisons", raising=False)
    page = report_page(study_dir).render()
    assert "Paired comparisons</h2>" not in page
    assert "No paired comparisons in this directory." in page
    for t in ("mht-gmm", "mht-agmm"):
        runs = [pq.read_table(study_dir / "runs" / t / f"run-{i}.parquet") for i in range(3)]
        v = np.array([float(r.column("ospa_mean")[0].as_py()) for r in runs])
        assert f"{v.mean():.4g} ± {v.std():.4g} m" in page


def test_study_paired_from_a_json_file(study_dir, tmp_path, monkeypatch):
    monkeypatch.delattr(montecarlo, "paired_comparisons", raising=False)
    d = tmp_path / "mc"
    shutil.copytree(study_dir, d)
    (d / "results.json").write_text(json.dumps({"paired": PAIRED, "other": 1}))
    page = report_page(d).render()
    assert "Paired comparisons</h2>" in page and "Source: results.json." in page
    assert ("<td>ospa_mean ↓</td><td>mht-agmm</td><td>mht-gmm</td><td class=\"num\">3</td>"
            "<td class=\"num\">-4.0</td><td>[-7.5, -0.5]</td><td>better</td>") in page
    # the text reports' format (metrics.paired.difference_texts): ospa_mean with 1
    # decimal, rcc with 4 (montecarlo.PAIRED_METRICS); no interval: a dash
    assert ("<td class=\"num\">+0.0100</td><td>–</td>"
            "<td>no detectable difference</td>") in page
    assert "<li>mht-agmm is better than mht-gmm</li>" in page


def test_study_paired_from_the_montecarlo_report(study_dir, monkeypatch):
    class Comparison:
        def __init__(self, d):
            self.d = d

        def to_dict(self):
            return dict(self.d)

    seen = []

    def paired_comparisons(result):
        seen.append(result.spec.trackers)
        return [Comparison(PAIRED[0])]

    monkeypatch.setattr(montecarlo, "paired_comparisons", paired_comparisons, raising=False)
    page = report_page(study_dir).render()
    assert seen == [("mht-gmm", "mht-agmm")]
    assert "Source: mhtrack.metrics.paired on the runs." in page


def test_missing_plotly_is_one_clear_line(run_dir, monkeypatch):
    monkeypatch.setitem(sys.modules, "plotly", None)
    with pytest.raises(ImportError, match=r'pip install "mhtrack\[report\]"'):
        report_page(run_dir)
    code, _, err = invoke("report", str(run_dir))
    assert code == 1
    assert err.strip().splitlines() == [
        'Error: the HTML report needs Plotly: pip install "mhtrack[report]" '
        "(or pip install plotly)"]


def test_cli_report_bad_input(tmp_path, run_dir):
    code, _, err = invoke("report", str(tmp_path))
    assert code == 2 and "holds no plots, truth or tracks file" in err
    code, _, err = invoke("report", str(run_dir), "-o", str(tmp_path / "r.png"))
    assert code == 2 and "unknown extension '.png'" in err
    code, out, err = invoke("report", str(run_dir), "-o", str(tmp_path / "r.html"))
    assert code == 0 and out.strip() == f"wrote {tmp_path / 'r.html'}"


def test_run_json_with_report_keeps_stdout_json(tmp_path):
    out = tmp_path / "r"
    code, stdout, stderr = invoke("run", "crossing", "--seed", "2", "--scans", "12", "--out",
                                  str(out), "--json", "--report", "--no-progress")
    assert code == 0, stderr
    assert json.loads(stdout)["tracker"] == "mht-agmm"
    assert f"wrote {out / REPORT_FILE}" in stderr and (out / REPORT_FILE).is_file()


def test_coastlines_in_a_geographic_scene(geo_dir, cached_coastlines):
    """The fixture's lines near the scene, through the sensors' frame; the far one
    (Japan) left out; the page names the source and the cache."""
    from mhtrack.io import read_tracks
    from mhtrack.io.sensors import read_sensors
    from mhtrack.reports.html_scene import basemap_traces

    frame = read_sensors(geo_dir / "sensors.toml").frame()
    html = report_page(geo_dir, coastlines=True).render()
    assert "Coastlines and borders: Natural Earth 1:50m (public domain), from " \
           f"{cached_coastlines}." in html
    assert '"name":"coastlines"' in html and '"name":"borders"' in html
    assert report_page(geo_dir).render().count('"name":"coastlines"') == 0  # off by default
    from mhtrack.io.basemap import basemap

    layers, _ = basemap(fetch=False)
    t = read_tracks(geo_dir / "tracks.csv")
    box = (float(t.x.min()), float(t.x.max()), float(t.y.min()), float(t.y.max()))
    coast, borders = basemap_traces(layers, frame, box, 1000.0)
    x, y = (np.asarray(coast[k], float) for k in ("x", "y"))
    ex, ey = frame.to_local([50.5, 50.6, 50.8, 51.2], [-4.0, -2.0, 0.0, 1.0])
    assert np.allclose(x[:4] * 1000, ex, atol=1.0) and np.allclose(y[:4] * 1000, ey, atol=1.0)
    assert np.isnan(x[4])  # a gap between lines
    far_x, _ = frame.to_local(35.0, 140.0)
    assert not np.any(np.isclose(x * 1000, far_x, atol=1000.0))
    assert np.count_nonzero(~np.isnan(np.asarray(borders["x"], float))) == 4


def test_coastlines_off_where_unavailable_or_flat(geo_dir, run_dir, tmp_path, monkeypatch):
    from mhtrack.io import basemap

    monkeypatch.setenv("MHTRACK_CACHE", str(tmp_path / "empty"))

    def unreachable(url):
        raise OSError("Network is unreachable")

    monkeypatch.setattr(basemap, "_download", unreachable)
    html = report_page(geo_dir, coastlines=True).render()
    assert "Coastlines off: ne_50m_coastline.geojson could not be downloaded (Network is " \
           "unreachable)." in html and '"name":"coastlines"' not in html
    flat = report_page(run_dir, coastlines=True).render()
    assert "Coastlines off: the scene has no geodetic origin" in flat


def test_report_command_coastlines_flag(geo_dir, tmp_path, cached_coastlines):
    """``mhtrack report DIR --coastlines`` draws the cached layers; without the flag the
    page has none."""
    d = tmp_path / "geo"
    shutil.copytree(geo_dir, d)
    code, _, err = invoke("report", str(d), "--coastlines", "--out", str(d / "c.html"),
                          "--quiet")
    assert code == 0, err
    assert '"name":"coastlines"' in (d / "c.html").read_text()
    code, _, err = invoke("report", str(d), "--out", str(d / "n.html"), "--quiet")
    assert code == 0, err
    assert '"name":"coastlines"' not in (d / "n.html").read_text()


def test_run_report_takes_the_report_page_options(tmp_path, cached_coastlines):
    """``run --report --coastlines --plotlyjs file`` writes the page as ``report`` does
    with the same options (the layers from the local cache, plotly.js beside the page);
    without ``--report`` the page options are a usage error naming it."""
    d = tmp_path / "r"
    code, _, err = invoke("run", "opensky-radars", "--seed", "1", "--scans", "2", "--out",
                          str(d), "--report", "--coastlines", "--plotlyjs", "file",
                          "--quiet")
    assert code == 0, err
    page = (d / "report.html").read_text()
    assert '"name":"coastlines"' in page and '"name":"borders"' in page
    assert list(d.glob("plotly-*.min.js"))
    code, _, err = invoke("report", str(d), "--coastlines", "--plotlyjs", "file", "--out",
                          str(d / "again.html"), "--quiet")
    assert code == 0, err
    assert _scene(page) == _scene((d / "again.html").read_text())
    code, _, err = invoke("run", "radars-clutter", "--scans", "3", "--out",
                          str(tmp_path / "x"), "--coastlines")
    assert code == 2 and "--report" in err


def _scene(page: str) -> str:
    """The scene figure's JSON of a page (its div and script)."""
    return re.search(r'id="fig-scene".*?</script>', page, re.S)[0]
