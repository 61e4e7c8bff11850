"""``mhtrack export TRACKS --category 062``: a tracks file as a CAT062 recording of
system tracks (:mod:`.cat062`: the items and their values; docs/file-formats.md,
"System tracks as CAT062"), encoded by the CAT062 sinks' encoder
(:func:`~mhtrack.io.asterix.cat062_fast.row_blocks`) and written atomically.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import mhtrack.io.asterix._lib as _lib
from mhtrack.io._frame import FLOAT, INT, TIME, read_frame
from mhtrack.io._times import seconds
from mhtrack.io.asterix.cat062_fast import row_blocks
from mhtrack.io.asterix.writer import write_blocks
from mhtrack.io.track_attributes import KINDS, read_track_attributes
from mhtrack.models.radars import SensorSet
from mhtrack.progress import Count

_TRACKS = {"time": TIME, "track_id": INT, "lat": FLOAT, "lon": FLOAT, "x": FLOAT,
           "y": FLOAT, "vx": FLOAT, "vy": FLOAT, "plot": INT, "tentative": INT} | KINDS


def export_tracks(tracks: str | Path, sensors: SensorSet | None, out: str | Path, *,
                  sac: int | None = None, sic: int | None = None,
                  progress: bool = False) -> tuple[int, int]:
    """Encode a tracks file as CAT062 system tracks from data source ``sac``/``sic``
    (default :data:`~mhtrack.io.asterix.cat062.DEFAULT_SAC`, ``DEFAULT_SIC``);
    positions from ``lat, lon`` (else ``x, y`` through the sensors file's frame),
    velocities east/north. Returns ``(track rows, data blocks)``. ``progress``: a bar
    of the rows encoded. Encoded by :func:`~mhtrack.io.asterix.cat062_fast.row_blocks`,
    as the CAT062 sinks encode. libasterix stays required: the items' LSBs are read
    from it (:func:`~mhtrack.io.asterix.cat062.lsb062`), and it encodes the attribute
    values the NumPy encoder does not cover (of rows in memory: a tracks file cannot
    hold them, its reader refuses them)."""
    _lib.modules()
    f = read_frame(tracks, _TRACKS, ("time", "track_id"), "tracks")
    if f.n == 0:
        f.fail("no rows (nothing to export)")
    time = seconds(f)
    tn = f.ints("track_id")
    if f.has("lat") and f.has("lon"):
        lat, lon = f.floats("lat"), f.floats("lon")
        ve = f.floats("vx") if f.has("vx") else np.zeros(f.n)
        vn = f.floats("vy") if f.has("vy") else np.zeros(f.n)
    else:
        if sensors is None or sensors.reference is None:
            f.fail("no lat/lon columns: give the sensors file whose frame the x, y are in")
        frame = sensors.frame()  # type: ignore[union-attr]
        x, y = f.floats("x"), f.floats("y")
        lat, lon = frame.to_geodetic(x, y)
        vx = f.floats("vx") if f.has("vx") else np.zeros(f.n)
        vy = f.floats("vy") if f.has("vy") else np.zeros(f.n)
        ve, vn = frame.velocity_to_geodetic(x, y, vx, vy)
    coasting = (f.ints("plot", nullable=True) < 0).astype(int) if f.has("plot") \
        else np.zeros(f.n, int)
    tentative = (f.ints("tentative", nullable=True, fill=0) != 0).astype(int) \
        if f.has("tentative") else np.zeros(f.n, int)
    values = (time, tn, lat, lon, ve, vn, coasting, tentative, f.check)
    attrs = read_track_attributes(f)
    with Count(f.n, "export", "row", progress) as bar:
        n = write_blocks(out, row_blocks(values, attrs, sac=sac, sic=sic, bar=bar))
    return f.n, n
