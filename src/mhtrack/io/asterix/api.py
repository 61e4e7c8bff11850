"""Convert and export: an ASTERIX recording to a plots table, and a plots table (with its
sensors file) to an ASTERIX recording (docs/file-formats.md, "ASTERIX recordings")."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pyarrow as pa

import mhtrack.io.asterix._lib as _lib
from mhtrack.errors import InputError
from mhtrack.io._frame import FLOAT, INT, TIME, float_array, int_array, read_frame, write_frame
from mhtrack.io._source import FORMATS
from mhtrack.io._times import seconds
from mhtrack.io.asterix.decode import (
    ADSB_EXTRA,
    CHARACTERISTICS,
    FL_M,
    PLOT_COLUMNS,
    Decoder,
    Recording,
    read_recording,
)
from mhtrack.io.asterix.earth import ground_range, slant_range
from mhtrack.io.asterix.encode import encode_blocks, plot_messages, sweep_messages
from mhtrack.io.asterix.notplots import PLOT_TYPES
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.writer import write_blocks
from mhtrack.models.radars import SensorSet
from mhtrack.names import EXPORT_CATEGORIES
from mhtrack.progress import Count

#: Largest sensor id an ASTERIX data source holds (SAC·256 + SIC).
MAX_SENSOR_ID = 0xFFFF
_TEXT = ("mode_3a", "address", "callsign")


def is_recording(path: str | Path) -> bool:
    """Whether ``path`` is to be read as an ASTERIX recording: not a ``.csv``/``.parquet``
    table, and its first 64 KiB recognised as a framing
    (:func:`~mhtrack.io.asterix.framings.recognise`: pcap, pcapng, Final, ORADIS, GPS; a
    raw stream only when the reading path finds a data block in them,
    :func:`_finds_blocks`) — or named like a recording (``.ast``, ``.pcap``, ...), so
    that a damaged one gets the decoder's message."""
    from mhtrack.io.asterix.framings import PCAP_MAGICS, PCAPNG_MAGIC, recognise

    p = Path(path)
    if p.suffix.lower() in FORMATS or not p.is_file():
        return False
    with p.open("rb") as fh:
        head = fh.read(1 << 16)
    if head[:4] in PCAP_MAGICS or head[:4] == PCAPNG_MAGIC:
        return True
    try:
        decoder = Decoder(duplicates=None)
    except _lib.MissingExtra:  # framing alone: the reader then names the missing extra
        decoder = None
    try:
        kind = recognise(head, str(p), _READ if decoder is None else decoder.categories)
    except InputError:
        kind = ""
    if kind in ("final", "oradis", "gps") or (kind == "raw" and (
            decoder is None or _finds_blocks(decoder, head, str(p)))):
        return True
    return p.suffix.lower() in (".ast", ".asterix", ".pcap", ".pcapng", ".raw", ".ff",
                                ".gps")


#: Categories whose data blocks mhtrack reads.
_READ = {1, 2, 21, 34, 48, 62}


#: Bytes of a file's head the raw sniff reads blocks in: a few UDP datagrams' worth, so
#: that random bytes shaped like a block header are refused in about a second (the
#: reading path judges every offset after damage; 64 KiB took ~10 s).
SNIFF_RAW = 1 << 13


def _finds_blocks(decoder: Decoder, head: bytes, name: str) -> bool:
    """The reading path of every recording (:meth:`Decoder.units`: framing, then each
    block judged by its content, reading on after damage) finds a data block in the
    first :data:`SNIFF_RAW` bytes of ``head`` (any one: a damaged first block does not
    hide the good ones after it)."""
    units = decoder.units(head[:SNIFF_RAW], "raw", name, Problems())
    return next(iter(units), None) is not None


def add_ground_range(rec: Recording, sensors: SensorSet) -> np.ndarray:
    """The ``range`` column (m) of a recording's plots (:func:`ground_ranges`)."""
    p = rec.plots
    return ground_ranges(sensors, p["sensor"], p["slant_range"], p["bearing"],
                         p["flight_level"])


def ground_ranges(sensors: SensorSet, sensor: np.ndarray, slant: np.ndarray,
                  bearing: np.ndarray, flight_level: np.ndarray) -> np.ndarray:
    """Ground range (m) of plots: from slant range, flight level and the site's ``alt``
    (:mod:`~mhtrack.io.asterix.earth`; ``alt`` absent = 0 m, flight level absent = the
    site's height); NaN for a sensor the file does not list or that has no geodetic
    site. Element-wise (the sources convert chunk by chunk)."""
    out = np.full(sensor.size, np.nan)
    for sid in np.unique(sensor).tolist():
        if sid not in sensors.ids or sensors.sensor(sid).lat is None:
            continue
        s = sensors.sensor(sid)
        rows = sensor == sid
        alt = float(s.alt or 0.0)
        h = np.where(np.isnan(flight_level[rows]), alt, flight_level[rows] * FL_M)
        out[rows] = ground_range(slant[rows], bearing[rows], h, float(s.lat),
                                 alt)  # type: ignore[arg-type]
    return out


def plot_columns(rec: Recording, sensors: SensorSet | None = None) -> dict[str, pa.Array]:
    """The plots table of a recording, columns in output order: :data:`PLOT_COLUMNS`,
    then ``lat, lon, sigma`` when it holds ADS-B reports, the I048/130 columns
    (:data:`~mhtrack.io.asterix.decode.CHARACTERISTICS`) when a plot has them, ``range`` last (with
    ``sensors``); empty text, ``-1`` ints and NaN become empty cells."""
    p = rec.plots
    cols: dict[str, pa.Array] = {}
    for name in (*PLOT_COLUMNS, *(c for c in (*ADSB_EXTRA, *CHARACTERISTICS) if c in p)):
        v = p[name]
        if name.endswith("_vg"):  # 2·V + G → the V and G columns, where any is set
            base = name[:-3]
            for bit, shift in (("v", 1), ("g", 0)):
                flag = (v >> shift) & 1
                if flag.any():
                    cols[f"{base}_{bit}"] = int_array(flag)
            continue
        if name in _TEXT:
            cols[name] = pa.array(v.tolist(), type=pa.string(), mask=v == "")
        elif name == "plot_type":  # the name of the type: primary, secondary, ...
            cols[name] = pa.array([PLOT_TYPES.get(int(k), "none") for k in v.tolist()],
                                  type=pa.string())
        elif v.dtype.kind == "i":
            cols[name] = int_array(v, v < 0 if name in ("track_number", "typ") else None)
        else:
            cols[name] = float_array(v, nan_as_null=True)
    if sensors is not None:
        cols["range"] = float_array(add_ground_range(rec, sensors), nan_as_null=True)
    return cols


@dataclass(frozen=True)
class Converted:
    """What :func:`convert` did: plots written, the recording (its problems, periods)."""

    n_plots: int
    recording: Recording

    def describe(self) -> str:
        """One line: container, plots, radars (SAC/SIC), ADS-B reports and stations (when
        any), CAT034 sweep marks and periods."""
        rec = self.recording
        p = rec.plots
        adsb = np.isfinite(p["lat"]) if "lat" in p else np.zeros(len(rec), bool)

        def ids(rows: np.ndarray) -> str:
            return ", ".join(f"{s >> 8}/{s & 0xFF}"
                             for s in sorted(set(p["sensor"][rows].tolist())))

        periods = ", ".join(f"{s}: {v:.3g} s" for s, v in sorted(rec.periods().items()))
        stations = (f"; {int(adsb.sum())} ADS-B reports (CAT021) from stations "
                    f"{ids(adsb)}" if adsb.any() else "")
        return (f"{rec.container} recording: {self.n_plots - int(adsb.sum())} plots from "
                f"radars (SAC/SIC) {ids(~adsb)}{stations}; {rec.sweeps['time'].size} CAT034 "
                "sweep marks" + (f" (periods {periods})" if periods else ""))


def convert(source: str | Path, out: str | Path, sensors: SensorSet | None = None, *,
            recording: Recording | None = None, progress: bool = False) -> Converted:
    """Decode ``source`` (warning one line per kind of part skipped) and write its plots
    and ADS-B reports to ``out`` (CSV or Parquet; :func:`plot_columns`); ``recording``:
    ``source`` already decoded; ``progress``: a bar of the bytes decoded."""
    if recording is None:
        recording = read_recording(source, progress=progress)
        recording.problems.warn(str(source))
    rec = recording
    if len(rec) == 0:
        raise InputError(f"{source}: no CAT048 plot with a measured position (I048/040) "
                         f"nor CAT021 report in this {rec.container} recording",
                         file=str(source))
    write_frame(out, plot_columns(rec, sensors))
    return Converted(len(rec), rec)


def sensors_with_periods(sensors: SensorSet, rec: Recording | dict[int, float]
                         ) -> SensorSet:
    """``sensors`` with the rotation periods the recording's CAT034 messages give (a
    :class:`Recording`, or its periods) filled in where the file has none (they set the
    length of the tracker's frames)."""
    found = rec.periods() if isinstance(rec, Recording) else rec
    radars = tuple(replace(s, period=found[s.id]) if s.period is None and s.id in found
                   else s for s in sensors.sensors)
    return replace(sensors, sensors=radars)


# --- export -----------------------------------------------------------------------------

@dataclass(frozen=True)
class Exported:
    """What :func:`export_file` wrote."""

    n_rows: int
    n_blocks: int
    category: str

    def describe(self) -> str:
        """``N plots|track updates in B data blocks (CAT…)``."""
        if self.category == "062":
            return f"{self.n_rows} track updates in {self.n_blocks} data blocks (CAT062)"
        return f"{self.n_rows} plots in {self.n_blocks} data blocks (CAT048, CAT034)"


def export_file(path: str | Path, sensors: SensorSet | None, out: str | Path, *,
                category: str | None = None, sac: int | None = None,
                sic: int | None = None, progress: bool = False) -> Exported:
    """``mhtrack export`` (:data:`~mhtrack.names.EXPORT_CATEGORIES`, the first the
    default): timed plots as CAT048 target reports with CAT034 sweeps (:func:`export`;
    needs ``sensors``), or with ``category "062"`` a tracks file as CAT062 system tracks
    from data source ``sac``/``sic``
    (:func:`~mhtrack.io.asterix.cat062_export.export_tracks`). ``progress``: a bar of
    the rows encoded."""
    from mhtrack.io.asterix.cat062_export import export_tracks

    category = EXPORT_CATEGORIES[0] if category is None else category
    if category not in EXPORT_CATEGORIES:
        raise ValueError(f"unknown category {category!r} (expected "
                         f"{', '.join(EXPORT_CATEGORIES)})")
    if category == "062":
        return Exported(*export_tracks(path, sensors, out, sac=sac, sic=sic,
                                       progress=progress), category)
    if sensors is None:
        raise ValueError("export of plots (CAT048) needs --sensors FILE")
    return Exported(*export(path, sensors, out, progress=progress), category)


_EXPORT = {"time": TIME, "sensor": INT, "range": FLOAT, "slant_range": FLOAT,
           "bearing": FLOAT, "flight_level": FLOAT, "typ": INT, "track_number": INT,
           "mode_3a": TIME, "address": TIME, "callsign": TIME, "plot_type": TIME,
           "mode_3a_v": INT, "mode_3a_g": INT, "flight_level_v": INT,
           "flight_level_g": INT}  # TIME: read as text
#: I048/020 TYP written for a ``plot_type`` name when the file has no ``typ`` column.
_TYP_OF = {"primary": 1, "secondary": 2, "combined": 3, "mode_s": 5}


def export(plots: str | Path, sensors: SensorSet, out: str | Path, *,
           progress: bool = False) -> tuple[int, int]:
    """Encode a timed plots file (``time, sensor, bearing`` and ``slant_range`` or
    ``range``) as CAT048 with CAT034 sweep marks of the radars with a ``period``;
    ``out`` ``.pcap`` or raw. Returns ``(plots, data blocks)`` written. ``progress``: a
    bar of the plots encoded (:func:`~mhtrack.io.asterix.encode.encode_blocks`)."""
    _lib.modules()
    f = read_frame(plots, _EXPORT, ("time", "sensor", "bearing"), "timed plots")
    if f.n == 0:
        f.fail("no rows (nothing to export)")
    if not (f.has("range") or f.has("slant_range")):
        f.fail("missing column 'range' or 'slant_range' (export writes polar plots)")
    time = seconds(f)
    f.check(time < 0, "time", lambda r: f"time {time[r]:g} s is negative (ASTERIX times "
            "are times of day)")
    sensor = f.ints("sensor")
    f.check((sensor < 0) | (sensor > MAX_SENSOR_ID), "sensor", lambda r: f"sensor "
            f"{sensor[r]} is not a data source id SAC·256 + SIC in [0, 65535]")
    f.check(~np.isin(sensor, np.asarray(sensors.ids, np.int64)), "sensor", lambda r: (
        f"unknown sensor {sensor[r]} (the sensors file lists "
        f"{', '.join(map(str, sensors.ids))})"))
    bearing = f.floats("bearing")
    extra: dict[str, np.ndarray] = {}
    if f.has("flight_level"):
        extra["flight_level"] = f.floats("flight_level", nullable=True)
    for name in ("typ", "track_number", "mode_3a_v", "mode_3a_g", "flight_level_v",
                 "flight_level_g"):
        if f.has(name):
            extra[name] = f.ints(name, nullable=True, fill=-1 if name in (
                "typ", "track_number") else 0)
    if f.has("plot_type") and "typ" not in extra:
        names = ["" if s is None else str(s) for s in f.table.column("plot_type").to_pylist()]
        extra["typ"] = np.array([_TYP_OF.get(s, -1) for s in names], np.int64)
    for name in _TEXT:
        if f.has(name):
            extra[name] = np.array(f.table.column(name).to_pylist(), dtype=object)
    if f.has("slant_range"):
        slant = f.floats("slant_range")
    else:
        ground = f.floats("range")
        slant = np.empty(f.n)
        fl = extra.get("flight_level", np.full(f.n, np.nan))
        for sid in np.unique(sensor).tolist():
            s = sensors.sensor(sid)
            rows = sensor == sid
            if s.lat is None:
                f.fail(f"sensor {sid} has no lat/lon site in the sensors file (needed to "
                       "turn ground range into slant range)", row=int(np.argmax(rows)),
                       column="sensor")
            alt = float(s.alt or 0.0)
            h = np.where(np.isnan(fl[rows]), alt, fl[rows] * FL_M)
            slant[rows] = slant_range(ground[rows], bearing[rows], h, float(s.lat), alt)
    try:
        messages = plot_messages(time, sensor, slant, bearing, extra)
    except ValueError as e:
        raise InputError(f"{plots}: {e}", file=str(plots)) from None
    periods = {s.id: float(s.period) for s in sensors.sensors if s.period is not None}
    messages += sweep_messages(time, sensor, bearing, periods)
    with Count(f.n, "export", "row", progress) as bar:
        n = write_blocks(out, encode_blocks(messages, bar))
    return f.n, n
