"""Coastlines and borders (:mod:`mhtrack.io.basemap`): GeoJSON lines read as worked by
hand from the tiny fixture files (tests/io/data/naturalearth, in the form of Natural
Earth's files), the cache filled once, and every layer off with its reason where
unavailable. Nothing here touches the network: every download is a function of the
test."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from mhtrack.errors import InputError
from mhtrack.io import basemap as bm

FIXTURE = Path(__file__).parent / "data" / "naturalearth"


def _no_network(url: str) -> bytes:
    raise AssertionError(f"a test tried to download {url}")


def test_lines_of_the_fixture_are_lat_lon():
    coast = bm.read_lines(FIXTURE / bm.LAYERS["coastlines"])
    assert [line.tolist() for line in coast] == [
        [[50.5, -4.0], [50.6, -2.0], [50.8, 0.0], [51.2, 1.0]],
        [[53.2, -3.0], [53.4, -2.8]], [[53.0, 0.2], [53.6, 0.4]],
        [[35.0, 140.0], [36.0, 141.0]]]
    ring = bm.read_lines(FIXTURE / bm.LAYERS["borders"])
    assert [line.tolist() for line in ring] == [
        [[52.0, -3.5], [52.5, -3.0], [53.0, -3.2], [52.0, -3.5]]]


def test_geometry_kinds(tmp_path):
    doc = {"type": "GeometryCollection", "geometries": [
        {"type": "Point", "coordinates": [1, 2]},
        {"type": "MultiPolygon", "coordinates": [[[[0, 0], [1, 0], [0, 1], [0, 0]]],
                                                 [[[5, 5], [6, 5], [5, 6], [5, 5]]]]}]}
    p = tmp_path / "g.geojson"
    p.write_text(json.dumps(doc))
    lines = bm.read_lines(p)
    assert len(lines) == 2 and lines[1][0].tolist() == [5.0, 5.0]


@pytest.mark.parametrize("geometry", [
    {"type": "LineString", "coordinates": [1, 2]},
    {"type": "LineString", "coordinates": [[0, 0], [1, "x"]]},
    {"type": "LineString", "coordinates": [[0, 0], [1, float("nan")]]},
    {"coordinates": [[0, 0]]}])
def test_a_bad_feature_is_named(tmp_path, geometry):
    p = tmp_path / "bad.geojson"
    p.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]}},
        {"type": "Feature", "geometry": geometry}]}))
    with pytest.raises(InputError, match=r"bad\.geojson: feature 1: ") as e:
        bm.read_lines(p)
    assert e.value.row == 1


def test_not_json_is_an_input_error(tmp_path):
    p = tmp_path / "x.geojson"
    p.write_text("{nope")
    with pytest.raises(InputError, match=r"x\.geojson: not a readable GeoJSON file"):
        bm.read_lines(p)


def test_cache_dir_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("MHTRACK_CACHE", str(tmp_path / "c"))
    assert bm.cache_dir() == tmp_path / "c" / "naturalearth"
    monkeypatch.delenv("MHTRACK_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "x"))
    assert bm.cache_dir() == tmp_path / "x" / "mhtrack" / "naturalearth"


def test_without_fetch_nothing_is_downloaded(tmp_path):
    layers, note = bm.basemap(fetch=False, directory=tmp_path, download=_no_network)
    assert layers == {}
    assert "Coastlines off:" in note and "Borders off:" in note and str(tmp_path) in note


def test_downloaded_once_then_read_from_the_cache(tmp_path):
    asked: list[str] = []

    def fake(url: str) -> bytes:
        asked.append(url)
        return (FIXTURE / url.rsplit("/", 1)[1]).read_bytes()

    layers, note = bm.basemap(fetch=True, directory=tmp_path, download=fake)
    assert asked == [bm.BASE_URL + name for name in bm.LAYERS.values()]
    assert set(layers) == {"coastlines", "borders"} and len(layers["coastlines"]) == 4
    assert note.startswith("Coastlines and borders: Natural Earth 1:50m (public domain)")
    for name in bm.LAYERS.values():  # cached byte for byte
        assert (tmp_path / name).read_bytes() == (FIXTURE / name).read_bytes()
    again, _ = bm.basemap(fetch=True, directory=tmp_path, download=_no_network)
    assert {k: [a.tolist() for a in v] for k, v in again.items()} == \
        {k: [a.tolist() for a in v] for k, v in layers.items()}


def test_unavailable_is_off_with_the_reason(tmp_path):
    asked: list[str] = []

    def refused(url: str) -> bytes:
        asked.append(url)
        raise OSError("Network is unreachable")

    layers, note = bm.basemap(fetch=True, directory=tmp_path, download=refused)
    assert layers == {} and len(asked) == 1  # after one failure no other try
    assert "Coastlines off: ne_50m_coastline.geojson could not be downloaded (Network " \
           "is unreachable)" in note
    assert "Borders off:" in note and not list(tmp_path.iterdir())  # nothing cached


def test_a_broken_answer_is_not_cached(tmp_path):
    layers, note = bm.basemap(fetch=True, directory=tmp_path,
                              download=lambda url: b"<html>rate limited</html>")
    assert layers == {} and "could not be downloaded" in note
    assert not list(tmp_path.iterdir())


def test_a_damaged_cached_file_turns_its_layer_off(tmp_path):
    shutil.copy(FIXTURE / bm.LAYERS["borders"], tmp_path)
    (tmp_path / bm.LAYERS["coastlines"]).write_text("{nope")
    layers, note = bm.basemap(fetch=True, directory=tmp_path, download=_no_network)
    assert set(layers) == {"borders"} and np.asarray(layers["borders"][0]).shape == (4, 2)
    assert "Coastlines off:" in note and "not a readable GeoJSON file" in note
