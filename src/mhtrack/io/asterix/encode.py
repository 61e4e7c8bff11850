"""Plots encoded as CAT048 target reports, with CAT034 north markers and sector crossings,
by libasterix (docs/file-formats.md, "ASTERIX recordings").

Each value is rounded to its item's LSB (taken from libasterix, :func:`lsb`) and checked
against the item's range before encoding, so that nothing wraps silently. Data blocks hold
the consecutive messages of one radar and one category, at most :data:`MAX_RECORDS`
records each (a block stays well under a 1 500-octet Ethernet frame).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix.decode import NM_M
from mhtrack.io.asterix.timeaxis import DAY_S
from mhtrack.progress import Count

#: Records per data block at most (CAT048 reports of up to ~30 octets each).
MAX_RECORDS = 40
#: Sector crossings per revolution written between north markers (45° sectors: the
#: tracker's frames, mhtrack.frames.SECTOR_FRACTION).
SECTORS = 8


@cache
def lsb() -> dict[str, float]:
    """LSBs from libasterix: an item created from raw 1, read back as a quantity."""
    c48, c34 = _lib.cat048().cv_record, _lib.cat034().cv_record
    polar = c48.spec("040").create((("RHO", 1), ("THETA", 1))).variation

    def q(item: Any, unit: str) -> float:
        return float(item.variation.content.as_quantity(unit))

    return {
        "rho_nm": q(polar.get_item("RHO"), "NM"),
        "theta_deg": q(polar.get_item("THETA"), "°"),
        "tod_s": q(c48.spec("140").create(1), "s"),
        "fl": q(c48.spec("090").create((0, 0, ("FL", 1))).variation.get_item("FL"), "FL"),
        "azimuth_deg": q(c34.spec("020").create(1), "°"),
        "period_s": q(c34.spec("041").create(1), "s"),
    }


@dataclass(frozen=True)
class Message:
    """One message to encode: ``time`` (s, the output's time scale), ``sensor``,
    ``category`` (48, 34 or 62) and its items (libasterix ``create`` arguments)."""

    time: float
    sensor: int
    category: int
    items: dict[str, Any]


def raw_tod(time: np.ndarray) -> np.ndarray:
    """Time of day in LSBs of 1/128 s: ``round(t / lsb) mod (86 400 / lsb)``."""
    step = lsb()["tod_s"]
    return np.mod(np.round(np.asarray(time, float) / step), round(DAY_S / step)).astype(
        np.int64)


def plot_messages(time: np.ndarray, sensor: np.ndarray, slant: np.ndarray,
                  bearing: np.ndarray, extra: dict[str, np.ndarray]) -> list[Message]:
    """CAT048 messages of plots (slant range m, bearing deg); ``extra`` may hold
    ``flight_level``, ``typ``, ``mode_3a``, ``address``, ``callsign``, ``track_number``
    (NaN, -1 or "" where absent) and the V, G bits of 070 and 090 (``mode_3a_v``,
    ``mode_3a_g``, ``flight_level_v``, ``flight_level_g``; 0 where absent). Raises
    ``ValueError`` naming the first plot out of an item's range."""
    L = lsb()
    rho = np.round(np.asarray(slant, float) / NM_M / L["rho_nm"]).astype(np.int64)
    _check(rho, 0, 0xFFFF, "slant range", slant, "m (I048/040 holds below 256 NM)")
    theta = np.mod(np.round(np.asarray(bearing, float) / L["theta_deg"]), 65536).astype(
        np.int64)
    tod = raw_tod(time)
    fl = extra.get("flight_level")
    fl_raw = None
    if fl is not None:
        fl_raw = np.round(np.where(np.isnan(fl), 0, fl) / L["fl"]).astype(np.int64)
        _check(np.where(np.isnan(fl), 0, fl_raw), -(1 << 13), (1 << 13) - 1,
               "flight level", fl, "(I048/090 holds -2048 to 2047.75)")
    out = []
    for i in range(len(time)):
        sid = int(sensor[i])
        items: dict[str, Any] = {
            "010": (("SAC", sid >> 8), ("SIC", sid & 0xFF)),
            "140": int(tod[i]),
            "020": ((("TYP", _int(extra, "typ", i, 1)), 0, 0, 0, 0, 0),),
            "040": (("RHO", int(rho[i])), ("THETA", int(theta[i]))),
        }
        m3a = _text(extra, "mode_3a", i)
        if m3a:
            items["070"] = (_int(extra, "mode_3a_v", i, 0), _int(extra, "mode_3a_g", i, 0),
                            0, 0, ("MODE3A", m3a))
        if fl_raw is not None and not np.isnan(fl[i]):  # type: ignore[index]
            items["090"] = (_int(extra, "flight_level_v", i, 0),
                            _int(extra, "flight_level_g", i, 0),
                            ("FL", int(fl_raw[i]) & 0x3FFF))
        address = _text(extra, "address", i)
        if address:
            items["220"] = int(address, 16)
        callsign = _text(extra, "callsign", i)
        if callsign:
            items["240"] = callsign.ljust(8)[:8]
        tn = _int(extra, "track_number", i, -1)
        if tn >= 0:
            items["161"] = (0, ("TRN", tn))
        out.append(Message(float(time[i]), sid, 48, items))
    return out


def _int(extra: dict[str, np.ndarray], name: str, i: int, default: int) -> int:
    v = extra.get(name)
    return default if v is None or v[i] < 0 else int(v[i])


def _text(extra: dict[str, np.ndarray], name: str, i: int) -> str:
    v = extra.get(name)
    return "" if v is None or v[i] is None else str(v[i])


def _check(raw: np.ndarray, lo: int, hi: int, what: str, values: np.ndarray,
           unit: str) -> None:
    bad = np.flatnonzero((raw < lo) | (raw > hi))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"plot {i}: {what} {values[i]:g} {unit}; {bad.size} plot(s) out "
                         "of range")


def sweep_messages(time: np.ndarray, sensor: np.ndarray, bearing: np.ndarray,
                   periods: dict[int, float]) -> list[Message]:
    """CAT034 north markers and :data:`SECTORS` sector crossings per revolution for each
    radar with a period, over its plots' span. The antenna's phase is the circular mean
    of ``t − θ/360 · P`` over its plots (a rotating radar times a plot when its beam
    crosses it)."""
    L = lsb()
    out = []
    for sid, period in sorted(periods.items()):
        mine = sensor == sid
        if not mine.any():
            continue
        t, b = time[mine], bearing[mine]
        angle = 2 * np.pi * np.mod(t - b / 360.0 * period, period) / period
        phase = np.mod(np.arctan2(np.sin(angle).mean(), np.cos(angle).mean()), 2 * np.pi)
        t0 = phase / (2 * np.pi) * period
        k0 = np.floor((t.min() - t0) / period)
        k1 = np.ceil((t.max() - t0) / period)
        ars = round(period / L["period_s"])
        for k in np.arange(k0, k1 + 1):
            for s in range(SECTORS):
                ts = t0 + (k + s / SECTORS) * period
                if ts < 0:
                    continue
                items: dict[str, Any] = {"000": 1 if s == 0 else 2,
                                         "010": (("SAC", sid >> 8), ("SIC", sid & 0xFF)),
                                         "030": int(raw_tod(np.array([ts]))[0])}
                if s:
                    items["020"] = round(360.0 * s / SECTORS / L["azimuth_deg"])
                elif ars <= 0xFFFF:
                    items["041"] = ars
                out.append(Message(float(ts), sid, 34, items))
    return out


def encode_blocks(messages: list[Message], bar: Count | None = None
                  ) -> Iterator[tuple[float, int, bytes]]:
    """``(time, sensor, data block bytes)`` of the messages in time order (stable: at
    equal times a sweep mark before the plots), runs of one radar and category per block.
    ``bar`` counts the rows (plots, track updates; not the CAT034 marks) encoded."""
    spec = {48: _lib.cat048(), 34: _lib.cat034(), 62: _lib.cat062()}
    order = sorted(range(len(messages)),
                   key=lambda i: (messages[i].time, messages[i].category != 34, i))
    run: list[Message] = []

    def flush() -> tuple[float, int, bytes]:
        s = spec[run[0].category]
        records = [s.cv_record.create(m.items) for m in run]
        if bar is not None and run[0].category != 34:
            bar.update(len(run))
        return run[0].time, run[0].sensor, s.create(records).unparse().to_bytes()

    for i in order:
        m = messages[i]
        if run and (m.sensor != run[0].sensor or m.category != run[0].category
                    or len(run) >= MAX_RECORDS):
            yield flush()
            run = []
        run.append(m)
    if run:
        yield flush()
