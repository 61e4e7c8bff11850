"""Coastlines and borders for the report's geographic scene (``docs/reports.md``,
*Coastlines and borders*): Natural Earth's 1:50m coastline and land-border lines, which
are in the public domain (naturalearthdata.com, *Terms of use*), as GeoJSON.

* **Cached once**: the files live in the user's cache directory, :func:`cache_dir`
  (``$MHTRACK_CACHE/naturalearth``, else ``$XDG_CACHE_HOME/mhtrack/naturalearth``, else
  ``~/.cache/mhtrack/naturalearth``). :func:`basemap` with ``fetch=True`` downloads a
  missing file once from :data:`BASE_URL` and writes it there atomically; any later
  report reads the cached copy and nothing else. A file copied there by hand (the same
  name) serves the same, for machines without network.
* **Off where unavailable**: no file and no download (no network, a refused or broken
  answer) turns the layer off; :func:`basemap` then says why in its note, and the report
  prints that note instead of the lines. Nothing fails.
* Without ``fetch`` (the tests, and every report not asking for coastlines) nothing is
  downloaded.

A GeoJSON file (RFC 7946: positions ``[lon, lat]`` in WGS-84 degrees) gives its lines:
every ``LineString`` and ``MultiLineString``, and the rings of every ``Polygon`` and
``MultiPolygon``, of its features (or of a bare geometry); a file that is not such
GeoJSON is an :class:`~mhtrack.errors.InputError` naming the file and the feature.
"""

from __future__ import annotations

import json
import os
import urllib.request
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.errors import InputError
from mhtrack.io.atomic import atomic_write

#: Layers and their Natural Earth files (1:50m).
LAYERS = {"coastlines": "ne_50m_coastline.geojson",
          "borders": "ne_50m_admin_0_boundary_lines_land.geojson"}
#: Where a missing file is downloaded from (Natural Earth's vector repository).
BASE_URL = "https://raw.githubusercontent.com/nvkelso/natural-earth-vector/master/geojson/"
#: Seconds a download may wait for an answer.
TIMEOUT_S = 30.0
SOURCE = "Natural Earth 1:50m (public domain)"

Lines = list[np.ndarray]


def cache_dir() -> Path:
    """The cache of the Natural Earth files (module docstring)."""
    if root := os.environ.get("MHTRACK_CACHE"):
        return Path(root) / "naturalearth"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "mhtrack" / "naturalearth"


def read_lines(path: str | Path) -> Lines:
    """The lines of a GeoJSON file, each an ``(n, 2)`` array of ``(lat, lon)`` degrees
    (module docstring)."""
    path = Path(path)
    try:
        data = json.loads(path.read_bytes())
    except (OSError, ValueError) as e:
        raise InputError(f"{path}: not a readable GeoJSON file ({e})", file=str(path)
                         ) from None
    if isinstance(data, dict) and data.get("type") == "FeatureCollection":
        geometries = [(i, f.get("geometry") if isinstance(f, dict) else f)
                      for i, f in enumerate(data.get("features") or [])]
    elif isinstance(data, dict) and data.get("type") == "Feature":
        geometries = [(0, data.get("geometry"))]
    else:
        geometries = [(0, data)]
    out: Lines = []
    for i, g in geometries:
        try:
            out += _geometry_lines(g)
        except (TypeError, ValueError, KeyError, IndexError) as e:
            raise InputError(f"{path}: feature {i}: not a GeoJSON line or polygon "
                             f"geometry ({e})", file=str(path), row=i) from None
    return out


def _geometry_lines(g: Any) -> Lines:
    if g is None:
        return []
    kind, coords = g["type"], g.get("coordinates")
    if kind == "GeometryCollection":
        return [line for sub in g["geometries"] for line in _geometry_lines(sub)]
    parts = {"LineString": lambda c: [c], "MultiLineString": lambda c: c,
             "Polygon": lambda c: c, "MultiPolygon": lambda c: [r for p in c for r in p]}
    if kind not in parts:
        return []  # points and the like: nothing to draw as a line
    lines = []
    for part in parts[kind](coords):
        a = np.asarray(part, float)
        if a.ndim != 2 or a.shape[1] < 2:
            raise ValueError(f"{kind} positions must be [lon, lat] pairs")
        if not np.isfinite(a[:, :2]).all():
            raise ValueError(f"{kind} has a position that is not a finite number")
        lines.append(np.column_stack([a[:, 1], a[:, 0]]))
    return lines


def _download(url: str) -> bytes:
    with urllib.request.urlopen(url, timeout=TIMEOUT_S) as r:
        return r.read()


def basemap(*, fetch: bool, directory: str | Path | None = None,
            download: Callable[[str], bytes] | None = None
            ) -> tuple[dict[str, Lines], str]:
    """The layers of :data:`LAYERS` that are available, and a note saying where they
    come from or why a layer is off. ``directory``: the cache (default
    :func:`cache_dir`); ``fetch``: download a missing file once (module docstring);
    ``download``: how (``url -> bytes``; default: HTTPS with the standard library)."""
    download = _download if download is None else download
    folder = Path(directory) if directory is not None else cache_dir()
    layers: dict[str, Lines] = {}
    off: list[str] = []
    unreachable: str | None = None  # after one failed download, try no other
    for layer, name in LAYERS.items():
        path = folder / name
        if not path.is_file():
            if not fetch:
                off.append(f"{layer} off: {path} is not there (ask for coastlines to "
                           "download it once)")
                continue
            if unreachable is not None:
                off.append(f"{layer} off: {name} not downloaded ({unreachable})")
                continue
            try:
                data = download(BASE_URL + name)
                json.loads(data)  # a broken answer is not cached
                atomic_write(path, data)
            except (OSError, ValueError) as e:
                unreachable = str(e)
                off.append(f"{layer} off: {name} could not be downloaded ({e})")
                continue
        try:
            layers[layer] = read_lines(path)
        except InputError as e:
            off.append(f"{layer} off: {e}")
    note = (f"{' and '.join(layers).capitalize()}: {SOURCE}, from {folder}." if layers
            else "")
    return layers, " ".join([note, *(s[0].upper() + s[1:] + "." for s in off)]).strip()
