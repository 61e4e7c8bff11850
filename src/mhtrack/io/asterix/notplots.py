"""Reports that are not plots of a real target, and the kind of plot each is
(docs/file-formats.md, "ASTERIX recordings").

A radar's target report is left out (and counted by reason) when it is

* ``no_detection`` — I048/020 TYP 0 ("no detection": a track extrapolated by the radar,
  sent without a plot), CAT001 I001/020 SSR/PSR 0;
* ``track`` — a CAT001 track report (I001/020 TYP 1), not a plot;
* ``test`` — a test target (I048/020 TST, CAT001 and CAT021 TST);
* ``field_monitor`` — a report from a fixed transponder (I048/020 RAB, "report from field
  monitor"; CAT001 and CAT021 RAB);
* ``simulated`` — a simulated target report (SIM).

Each report is counted under its first reason in that order. The plot type is kept as a
column (:data:`PLOT_TYPES`), from I048/020 TYP (EUROCONTROL CAT048 edition 1.32): 1 single
PSR → primary; 2 single SSR → secondary; 3 SSR + PSR → combined; 4 single Mode S All-Call,
5 single Mode S Roll-Call → Mode S; 6, 7 Mode S All-Call / Roll-Call + PSR → combined.
CAT001 I001/020 SSR/PSR 1, 2, 3 are primary, secondary, combined; CAT021 reports are ADS-B.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: Plot type codes of the ``plot_type`` column.
PLOT_TYPES = {0: "none", 1: "primary", 2: "secondary", 3: "combined", 4: "mode_s",
              5: "adsb"}
#: I048/020 TYP → plot type code.
TYP048 = np.array([0, 1, 2, 3, 4, 4, 3, 3])
#: Reasons, in the order a report is counted.
REASONS = ("no_detection", "track", "test", "field_monitor", "simulated")
#: Flag columns read from I048/020 / I001/020 (``-1`` where the item is absent).
FLAGS = ("typ", "sim", "rab", "tst")


def plot_type048(typ: np.ndarray) -> np.ndarray:
    """Plot type codes of I048/020 TYP values (``-1``, absent → 0, none)."""
    typ = np.asarray(typ, np.int64)
    return np.where((typ >= 0) & (typ <= 7), TYP048[np.clip(typ, 0, 7)], 0)


def plot_type048_of(typ: int) -> int:
    """:func:`plot_type048` of one TYP value (plain Python, per report)."""
    return _TYP048[typ] if 0 <= typ <= 7 else 0


_TYP048 = TYP048.tolist()


def _sub(var: Any, name: str) -> int:
    """A sub-item's value of an extended item, ``0`` when its extent was not sent."""
    try:
        item = var.get_item(name)
    except (KeyError, ValueError):
        return 0
    return 0 if item is None else int(item.variation.content.as_uint())


def flags048(rec: Any) -> tuple[int, int, int, int]:
    """``(typ, sim, rab, tst)`` of a libasterix CAT048 record's I048/020 (``-1`` each
    without the item; TST 0 when the first extension is not sent)."""
    i020 = rec.get_item("020")
    return (-1, -1, -1, -1) if i020 is None else flags048_item(i020)


def flags048_item(i020: Any) -> tuple[int, int, int, int]:
    """``(typ, sim, rab, tst)`` of a libasterix I048/020 item."""
    v = i020.variation
    return _sub(v, "TYP"), _sub(v, "SIM"), _sub(v, "RAB"), _sub(v, "TST")


def flags048_octets(octets: bytes) -> tuple[int, int, int, int]:
    """``(typ, sim, rab, tst)`` from the raw octets of I048/020 (for byte-level readers):
    first octet TYP bits 8–6, SIM bit 5, RAB bit 2, FX bit 1; TST bit 8 of the first
    extension, 0 when the FX bit does not announce it."""
    first = octets[0]
    tst = octets[1] >> 7 if first & 1 and len(octets) > 1 else 0
    return first >> 5, (first >> 4) & 1, (first >> 1) & 1, tst


def reason(typ: int, sim: int, rab: int, tst: int, track: int = 0) -> str | None:
    """Why a report is no plot of a real target — the first of :data:`REASONS` that holds
    — or ``None`` for a plot (flags ``-1``: unknown, kept). Plain Python: the decoder
    asks once per report."""
    if typ == 0:
        return "no_detection"
    if track == 1:
        return "track"
    if tst == 1:
        return "test"
    if rab == 1:
        return "field_monitor"
    if sim == 1:
        return "simulated"
    return None


def real_plots(typ: np.ndarray, sim: np.ndarray, rab: np.ndarray, tst: np.ndarray, *,
               track: np.ndarray | None = None) -> tuple[np.ndarray, dict[str, int]]:
    """The mask of reports that are plots of real targets, and the count of the others
    by reason (:data:`REASONS`; every reason present, zeros included): :func:`reason`'s
    rule, on whole columns. ``typ`` is the CAT048 TYP (CAT001: SSR/PSR, the same 0–3),
    ``-1`` where unknown (kept); ``track`` marks CAT001 track reports."""
    typ, sim, rab, tst = (np.asarray(a, np.int64).reshape(-1) for a in (typ, sim, rab, tst))
    trk = np.zeros(typ.size, np.int64) if track is None else \
        np.asarray(track, np.int64).reshape(-1)
    left, counts = np.ones(typ.size, bool), {}
    for name, hit in zip(REASONS, (typ == 0, trk == 1, tst == 1, rab == 1, sim == 1),
                         strict=True):  # each report under its first reason, in order
        counts[name] = int(np.count_nonzero(left & hit))
        left &= ~hit
    return left, counts
