"""The CAT062 items of a track's attributes (issue 29 item 5; EUROCONTROL ASTERIX
CAT062 edition 1.18, encoded by libasterix): I062/060 Mode 3/A code (V, G, CH 0: the
code kept is the last validated one), 136 measured flight level (1/4 FL), 220 rate of
climb (6.25 ft/min), 380 subfields ADR (24-bit address) and ID (callsign, up to eight
characters of the 6-bit ICAO set), 500 subfields APC (σ of x and y, 0.5 m) and COV
(``sign(Pxy) √|Pxy|``, 0.5 m), 245 target identification (STI 0 "downlinked from the
target": our callsigns come from Mode S replies, I048/240; CHR the callsign) and 290
system track update ages PSR, SSR and MDS (¼ s, 8 bits: an age beyond 63.75 s is written
as 63.75 s, saturated, as the item cannot hold more), and 340 measured information of
the row's own plot: SID (the sensor id as SAC·256 + SIC), POS (its measured range, 1/256
NM, and bearing, 360°/2¹⁶; a range beyond the item's 256 NM is not written), TYP (plot
type: 1 PSR, 2 SSR, 3 SSR + PSR, 5 Mode S — roll-call: all-call and roll-call replies
are not told apart here), MDA (the code as received with its V, G; L 0) and MDC (its
Mode C level, ¼ FL, with V, G). Each item only where its value is known. HEIGHT (the
height a 3-D radar measured) is not written: no plot source here gives one (Mode C is
MDC).

σx, σy and Pxy come from the tracks file's ellipse (σ major ``M``, minor ``m``, the
major axis' bearing ``β`` from north): with the axis ``u = (sin β, cos β)``,
``P = M² u uᵀ + m² v vᵀ``, so ``Pxx = M² sin²β + m² cos²β``, ``Pyy = M² cos²β + m²
sin²β``, ``Pxy = (M² − m²) sin β cos β``. σ beyond the items' 16 bits (32 767.5 m) is
written as the largest value (saturated).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

import numpy as np

import mhtrack.io.asterix._lib as _lib
from mhtrack.attributes import COMBINED, MODE_S, PRIMARY, SECONDARY, TrackAttributes, code_text

#: The international nautical mile (m).
NM = 1852.0
#: I062/340 TYP of our plot types.
TYP340 = {PRIMARY: 1, SECONDARY: 2, COMBINED: 3, MODE_S: 5}
#: Characters of I062/380 ID (ICAO 6-bit: A–Z, 0–9, space).
ID_CHARS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 ")


@cache
def lsb_attributes() -> dict[str, float]:
    """LSBs of the items written, from libasterix (raw 1 read back)."""
    rec = _lib.cat062().cv_record
    apc = rec.spec("500").cv_rule.cv_variation.cv_items_dict["APC"]
    return {"fl": float(rec.spec("136").create(1).variation.content.as_quantity("FL")),
            "fpm": float(rec.spec("220").create(1).variation.content.as_quantity("ft/min")),
            "m": float(apc.create((("X", 1), ("Y", 1))).variation.get_item("X")
                       .variation.content.as_quantity("m")),
            "age": float(rec.spec("290").create({"PSR": 1}).variation.get_item("PSR")
                         .variation.content.as_quantity("s")),
            **_lsb_pos(rec)}


def _lsb_pos(rec: Any) -> dict[str, float]:
    """LSBs of I062/340 POS: RHO (m, from NM of 1 852 m) and THETA (degrees)."""
    pos = rec.spec("340").cv_rule.cv_variation.cv_items_dict["POS"].create(
        (("RHO", 1), ("THETA", 1))).variation
    return {"rho_m": float(pos.get_item("RHO").variation.content.as_quantity("NM")) * NM,
            "theta_deg": float(pos.get_item("THETA").variation.content.as_quantity("°"))}


def cartesian(a: TrackAttributes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(σx, σy, Pxy)`` of the ellipses of ``a`` (module docstring)."""
    b = np.radians(a.sigma_orient)
    M2, m2 = a.sigma_major ** 2, a.sigma_minor ** 2
    s, c = np.sin(b), np.cos(b)
    return np.sqrt(M2 * s * s + m2 * c * c), np.sqrt(M2 * c * c + m2 * s * s), \
        (M2 - m2) * s * c


def attribute_raw(a: TrackAttributes, check: Callable[..., None]) -> dict[str, Any]:
    """The raw values (LSBs of :func:`lsb_attributes`) of the items of ``a`` (module
    docstring), computed for every row, with the rows' presence masks: ``fl`` (136),
    ``roc`` (220), ``names`` (380 ID, 245 CHR: upper case), ``ax, ay, cov, known`` (500),
    ``mfl, rho, theta, pos`` (340 MDC, POS) and ``ages`` (290: name → (known, raw));
    ``check(bad rows, column, message)`` reports values an item cannot hold (a flight
    level beyond −15…1 500 FL, a rate beyond ±204 793 ft/min, a callsign of other
    characters, a measured level beyond MDC, a sensor beyond SID), in that order."""
    L = lsb_attributes()
    fl = np.round(np.nan_to_num(a.flight_level) / L["fl"]).astype(np.int64)
    check(np.isfinite(a.flight_level) & ((fl < -60) | (fl > 6000)), "flight_level",
          lambda r: f"flight level {a.flight_level[r]:g} is outside I062/136's "
          "-15 to 1500 FL")
    roc = np.round(np.nan_to_num(a.rate_of_climb) / L["fpm"]).astype(np.int64)
    check(np.isfinite(a.rate_of_climb) & (np.abs(roc) > 0x7FFF), "rate_of_climb",
          lambda r: f"rate of climb {a.rate_of_climb[r]:g} ft/min beyond I062/220")
    names = [str(c).upper() for c in a.callsign.tolist()]
    check(np.array([len(n) > 8 or not set(n) <= ID_CHARS for n in names], bool),
          "callsign", lambda r: f"callsign {names[r]!r} is not up to eight of A-Z, 0-9, "
          "space (I062/380 ID)")
    sx, sy, cxy = cartesian(a)
    top = 0xFFFF

    def raw(v: np.ndarray, lo: int, hi: int) -> np.ndarray:
        return np.clip(np.round(np.nan_to_num(v) / L["m"]), lo, hi).astype(np.int64)

    mfl = np.round(np.nan_to_num(a.meas_flight_level) * 4).astype(np.int64)
    check(np.isfinite(a.meas_flight_level) & (np.abs(mfl) >= 1 << 13), "meas_flight_level",
          lambda r: f"measured flight level {a.meas_flight_level[r]:g} beyond I062/340 MDC")
    check(a.meas_sensor > 0xFFFF, "meas_sensor", lambda r: f"sensor {a.meas_sensor[r]} "
          "is not SAC·256 + SIC (I062/340 SID)")
    rho = np.round(np.nan_to_num(a.meas_range) / L["rho_m"]).astype(np.int64)
    theta = np.round(np.nan_to_num(a.meas_bearing) / L["theta_deg"]).astype(np.int64) % 65536
    return {"fl": fl, "roc": roc, "names": names, "ax": raw(sx, 0, top),
            "ay": raw(sy, 0, top),
            "cov": raw(np.sign(cxy) * np.sqrt(np.abs(cxy)), -0x8000, 0x7FFF),
            "known": np.isfinite(sx) & np.isfinite(sy), "mfl": mfl, "rho": rho,
            "theta": theta,
            "pos": np.isfinite(a.meas_range) & np.isfinite(a.meas_bearing) & (rho <= 0xFFFF),
            "ages": {k: (np.isfinite(v), np.clip(np.round(np.nan_to_num(v) / L["age"]), 0,
                                                 0xFF).astype(np.int64))
                     for k, v in (("PSR", a.age_psr), ("SSR", a.age_ssr),
                                  ("MDS", a.age_mds))}}


def attribute_items(a: TrackAttributes, check: Callable[..., None]
                    ) -> Callable[[int], dict[str, Any]]:
    """A function of a row giving its items (module docstring) for libasterix's
    ``create``, from :func:`attribute_raw` (which ``check`` s the values)."""
    v = attribute_raw(a, check)
    fl, roc, names, ages = v["fl"], v["roc"], v["names"], v["ages"]
    ax, ay, cov, known = v["ax"], v["ay"], v["cov"], v["known"]
    mfl, rho, theta, pos = v["mfl"], v["rho"], v["theta"], v["pos"]

    def items(i: int) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if a.mode_3a[i] >= 0:
            out["060"] = (0, 0, 0, 0, ("MODE3A", code_text(int(a.mode_3a[i]))))
        if np.isfinite(a.flight_level[i]):
            out["136"] = int(fl[i])
        if np.isfinite(a.rate_of_climb[i]):
            out["220"] = int(roc[i])
        adr: dict[str, Any] = {}
        if a.address[i] >= 0:
            adr["ADR"] = int(a.address[i])
        if names[i]:
            adr["ID"] = names[i].ljust(8)
        if adr:
            out["380"] = adr
        if names[i]:
            out["245"] = (("STI", 0), 0, ("CHR", names[i].ljust(8)))
        age = {k: int(raw_age[i]) for k, (has, raw_age) in ages.items() if has[i]}
        if age:
            out["290"] = age
        if a.meas_sensor[i] >= 0:
            out["340"] = measured_item(a, i, int(mfl[i]))
            if pos[i]:
                out["340"]["POS"] = (("RHO", int(rho[i])), ("THETA", int(theta[i])))
        if known[i]:
            out["500"] = {"APC": (("X", int(ax[i])), ("Y", int(ay[i]))),
                          "COV": int(cov[i])}
        return out

    return items


def measured_item(a: TrackAttributes, i: int, mfl: int) -> dict[str, Any]:
    """I062/340 of row ``i`` (module docstring), ``mfl`` its level in ¼ FL."""
    sensor = int(a.meas_sensor[i])
    out: dict[str, Any] = {"SID": (("SAC", sensor >> 8), ("SIC", sensor & 0xFF))}
    if int(a.meas_type[i]) in TYP340:
        out["TYP"] = (("TYP", TYP340[int(a.meas_type[i])]), ("SIM", 0), ("RAB", 0),
                      ("TST", 0), 0)
    if a.meas_mode_3a[i] >= 0:
        vg = int(a.meas_mode_3a_vg[i])
        out["MDA"] = (("V", vg >> 1), ("G", vg & 1), ("L", 0), 0,
                      ("MODE3A", code_text(int(a.meas_mode_3a[i]))))
    if np.isfinite(a.meas_flight_level[i]):
        vg = int(a.meas_flight_level_vg[i])
        out["MDC"] = (("V", vg >> 1), ("G", vg & 1), ("LMC", mfl))
    return out
