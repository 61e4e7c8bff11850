"""System tracks as ASTERIX CAT062 (issue 19, item 4): a tracks file encoded as I062/010
(the tracker's data source), 040 track number, 070 time of track information, 105
WGS-84 position, 185 Cartesian velocity (east, north) and 080 track status (CNF
tentative, CST coasting), by libasterix (edition 1.18); and read back
(:func:`read_system_tracks`) by the same library (docs/file-formats.md, "ASTERIX
recordings"). With the tracks' attributes (issue 29 item 5,
:class:`~mhtrack.attributes.TrackAttributes`) also, where known: 060 Mode 3/A code, 136
measured flight level, 220 rate of climb, 380 ADR (Mode S address) and ID (callsign),
500 APC and COV (the position's σx, σy and ``sign(Pxy) √|Pxy|``), 245 target
identification and 290 update ages per technology (PSR, SSR, Mode S;
:mod:`.cat062_items`).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

import mhtrack.io.asterix._lib as _lib
from mhtrack.errors import InputError
from mhtrack.io.asterix.cat062_items import attribute_items
from mhtrack.io.asterix.category_file import category_rows
from mhtrack.io.asterix.encode import Message, raw_tod
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import DAY_S, unwrap_days
from mhtrack.records import TrackTable

if TYPE_CHECKING:
    from mhtrack.attributes import TrackAttributes
    from mhtrack.models.geodesy import LocalFrame

#: Columns of :func:`read_system_tracks`.
TRACK_COLUMNS = ("time", "sac", "sic", "track_number", "lat", "lon", "vx", "vy",
                 "tentative", "coasting")


@cache
def lsb062() -> dict[str, float]:
    """LSBs of the CAT062 items written, from libasterix (raw 1 read back)."""
    rec = _lib.cat062().cv_record
    pos = rec.spec("105").create((("LAT", 1), ("LON", 1))).variation
    vel = rec.spec("185").create((("VX", 1), ("VY", 1))).variation
    return {"tod_s": float(rec.spec("070").create(1).variation.content.as_quantity("s")),
            "deg": float(pos.get_item("LAT").variation.content.as_quantity("°")),
            "mps": float(vel.get_item("VX").variation.content.as_quantity("m/s"))}


def _status(tentative: int, coasting: int) -> tuple[Any, ...]:
    """I062/080 with its first four extents: CNF (1 = tentative) and CST (1 = coasting);
    libasterix takes each extent as its items plus a placeholder for the FX bit."""
    return ((0, 0, 0, 0, ("CNF", tentative), None), (0, 0, 0, 0, 0, 0, 0, None),
            (0, 0, 0, 0, 0, None), (("CST", coasting), 0, 0, 0, 0, 0, 0, None))


#: The data source (I062/010) of exported system tracks when none is given.
DEFAULT_SAC = 0
DEFAULT_SIC = 1

#: ``check(bad rows, column, message of row r)``: raises on the first bad row.
Check = Callable[[np.ndarray, str, Callable[[int], str]], None]


def table_messages(tracks: TrackTable, frame: LocalFrame, name: str, *,
                   sac: int | None = None, sic: int | None = None) -> list[Message]:
    """The CAT062 messages of tracker output ``tracks`` (local ``x, y, vx, vy`` turned
    into WGS-84 and east/north by ``frame``, as a tracks file's ``lat, lon, vx, vy``;
    a miss is coasting, a ``tentative`` row tentative) — the same messages as of the
    tracks file written from ``tracks``
    (:func:`~mhtrack.io.asterix.cat062_export.export_tracks`). Problems raise
    :class:`ValueError` naming ``name``, the track and its time."""
    return track_messages(*table_values(tracks, frame, name), sac=sac, sic=sic,
                          attrs=tracks.attrs)


def table_values(tracks: TrackTable, frame: LocalFrame, name: str) -> tuple[Any, ...]:
    """The arguments of :func:`track_messages` (and :func:`core_raw`) for tracker
    output ``tracks`` (:func:`table_messages`), up to ``check``."""
    x, y = tracks.x, tracks.y
    lat, lon = frame.to_geodetic(x, y)
    ve, vn = frame.velocity_to_geodetic(x, y, tracks.vx, tracks.vy)
    coasting = (tracks.plot < 0).astype(int)
    tentative = (np.zeros(len(tracks), int) if tracks.tentative is None
                 else tracks.tentative.astype(int))

    def check(bad: np.ndarray, column: str, text: Callable[[int], str]) -> None:
        if bad.any():
            r = int(np.argmax(bad))
            raise ValueError(f"{name}: track {int(tracks.track_id[r])} at time "
                             f"{float(tracks.time[r]):g} s, {column}: {text(r)}")

    return (np.asarray(tracks.time, float), tracks.track_id, lat, lon, ve, vn, coasting,
            tentative, check)


def track_messages(time: np.ndarray, track_id: np.ndarray, lat: np.ndarray,
                   lon: np.ndarray, ve: np.ndarray, vn: np.ndarray, coasting: np.ndarray,
                   tentative: np.ndarray, check: Check, *, sac: int | None = None,
                   sic: int | None = None, attrs: TrackAttributes | None = None
                   ) -> list[Message]:
    """One CAT062 message per track row (I062/010, 070, 105, 185, 040, 080; with
    ``attrs`` the items of :func:`~mhtrack.io.asterix.cat062_items.attribute_items` where
    known), values rounded to the items' LSBs (:func:`lsb062`); ``check`` reports rows
    that do not fit."""
    r = core_raw(time, track_id, lat, lon, ve, vn, coasting, tentative, check, sac=sac,
                 sic=sic)
    sac, sic = r["sac"], r["sic"]
    extra = attribute_items(attrs, check) if attrs is not None else None
    return [Message(float(time[i]), r["sid"], 62, {
        "010": (("SAC", sac), ("SIC", sic)), "070": int(r["tod"][i]),
        "105": (("LAT", int(r["lat"][i])), ("LON", int(r["lon"][i]))),
        "185": (("VX", int(r["vx"][i])), ("VY", int(r["vy"][i]))),
        "040": int(r["track"][i]), "080": _status(int(tentative[i]), int(coasting[i])),
        **({} if extra is None else extra(i)),
    }) for i in range(len(time))]


def core_raw(time: np.ndarray, track_id: np.ndarray, lat: np.ndarray, lon: np.ndarray,
             ve: np.ndarray, vn: np.ndarray, coasting: np.ndarray, tentative: np.ndarray,
             check: Check, *, sac: int | None = None, sic: int | None = None
             ) -> dict[str, Any]:
    """The raw values (LSBs of :func:`lsb062`) of the items every row has — ``tod``
    (070), ``lat, lon`` (105), ``vx, vy`` (185), ``track`` (040) — and ``sac, sic,
    sid``; ``check`` reports rows that do not fit."""
    sac = DEFAULT_SAC if sac is None else sac
    sic = DEFAULT_SIC if sic is None else sic
    check(time < 0, "time", lambda r: f"time {time[r]:g} s is negative (ASTERIX times "
          "are times of day)")
    tn = np.asarray(track_id, np.int64)
    check((tn < 0) | (tn > 0xFFFF), "track_id", lambda r: f"track_id {tn[r]} does not "
          "fit I062/040 (0 to 65535)")
    L = lsb062()
    raw = {k: np.round(v / L["mps"]).astype(np.int64) for k, v in (("vx", ve), ("vy", vn))}
    for k, v in raw.items():
        check(np.abs(v) > 0x7FFF, "vx" if k == "vx" else "vy", lambda r, k=k: (
            f"velocity {k} beyond I062/185's ±8192 m/s"))
    lat_raw = np.round(lat / L["deg"]).astype(np.int64)
    lon_raw = np.round(((lon + 180.0) % 360.0 - 180.0) / L["deg"]).astype(np.int64)
    return {"tod": raw_tod(time), "lat": lat_raw, "lon": lon_raw, "vx": raw["vx"],
            "vy": raw["vy"], "track": tn, "sac": sac, "sic": sic, "sid": (sac << 8) | sic}


def read_system_tracks(path: str | Path) -> tuple[dict[str, np.ndarray], Problems]:
    """CAT062 records of a recording (any framing of :mod:`~mhtrack.io.asterix.framings`)
    as columns :data:`TRACK_COLUMNS`, with the parts skipped; times continued across
    midnight. A reference system's tracks for ``evaluate``: physically impossible records
    (|lat| > 90°, |lon| > 180°, time of day ≥ 86 400 s) are refused and counted
    (``impossible``), never passed on."""
    name = str(path)
    rows, problems = category_rows(path, 62, block062)
    if not rows:
        raise InputError(f"{name}: no CAT062 track with I062/010, 040, 070 and 105",
                         file=name)
    return track_columns(rows), problems


def track_columns(rows: list[tuple[Any, ...]]) -> dict[str, np.ndarray]:
    """Rows of :func:`block062` (at least one) as columns :data:`TRACK_COLUMNS`, times
    continued across midnight."""
    cols = {k: np.array(v) for k, v in zip(TRACK_COLUMNS, zip(*rows, strict=True),
                                             strict=True)}
    cols["time"] = unwrap_days(cols["time"].astype(float))
    return cols


def block062(raw: bytes, at: int, problems: Problems) -> list[tuple[Any, ...]] | None:
    """The track rows (:data:`TRACK_COLUMNS`, time of day) of one CAT062 data block, the
    impossible ones refused and counted; ``None`` when its records do not fill it."""
    base = _lib.modules()[0]
    records = _lib.cat062().cv_uap.parse(base.Bits.from_bytes(raw))
    if isinstance(records, ValueError):
        return None
    out = []
    for row in map(_track_row, records):
        if row is None:
            continue
        t, lat, lon = row[0], row[4], row[5]
        if abs(lat) > 90.0 or abs(lon) > 180.0 or not 0.0 <= t < DAY_S:
            problems.add("impossible", at, detail=f"CAT062 track {row[3]}: lat {lat:g}, "
                         f"lon {lon:g}, time {t:g} s")
            continue
        out.append(row)
    return out


def _track_row(rec: Any) -> tuple[Any, ...] | None:
    items = {k: rec.get_item(k) for k in ("010", "040", "070", "105", "185", "080")}
    if any(items[k] is None for k in ("010", "040", "070", "105")):
        return None

    def sub(k: str, s: str) -> Any:
        return items[k].variation.get_item(s).variation.content  # type: ignore[union-attr]

    vel = items["185"]
    vx = float(sub("185", "VX").as_quantity("m/s")) if vel is not None else np.nan
    vy = float(sub("185", "VY").as_quantity("m/s")) if vel is not None else np.nan
    status = items["080"]
    cnf = cst = -1
    if status is not None:
        c = status.variation.get_item("CNF")
        s = status.variation.get_item("CST")
        cnf = -1 if c is None else int(c.variation.content.as_uint())
        cst = -1 if s is None else int(s.variation.content.as_uint())
    return (float(items["070"].variation.content.as_quantity("s")),  # type: ignore[union-attr]
            int(sub("010", "SAC").as_uint()), int(sub("010", "SIC").as_uint()),
            int(items["040"].variation.content.as_uint()),  # type: ignore[union-attr]
            float(sub("105", "LAT").as_quantity("°")),
            float(sub("105", "LON").as_quantity("°")), vx, vy, cnf, cst)
