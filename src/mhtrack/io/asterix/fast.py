"""Faster CAT048 decoding on top of libasterix: decode only the needed items, and reuse
what libasterix found about a record's layout (benchmarks/bench_convert.py).

**Where libasterix's time goes** (cProfile, an exported hour of opensky-radars, 64 382
plots, 4 items per record): 58 % in ``Record._parse`` building an object per item and
subitem (``Bits.split_at``, ``NonSpare._parse``, ``Element/Group/Extended._parse``), 27 %
in reading the items back (``get_item``, ``as_quantity``), about 4 700 plots/s in all.

**Work-around, no codec written by hand.** Every fact about the bits comes from
libasterix, once:

* a record **layout** (its FSPEC octets and which items follow) is learnt from the first
  record libasterix parses with that FSPEC: each item's length, and whether libasterix's
  spec makes it fixed-size (``Element``, ``Group``) or variable (``Extended``,
  ``Compound``, ``Repetitive``, ``Explicit``). A later record that starts with the same
  FSPEC octets has the same items (the FSPEC's last octet ends the FSPEC);
* a **variable-size item** is matched against the encodings of that item libasterix has
  already parsed (a complete encoding that the data starts with parses to itself); a new
  one is parsed by libasterix at that offset and remembered (at most
  :data:`MAX_VARIANTS` per item, then always parsed);
* a **needed fixed-size field** (I048/010 SAC, SIC; 140; 040 RHO, THETA; 090 FL; 161 TRN;
  220) is read as ``raw × LSB`` with its bit offset, size, signedness and LSB taken from
  libasterix's spec classes (:func:`field`); text items (070, 240) and 020's flags are
  decoded by libasterix once per distinct encoding, as is I048/130 (radar plot
  characteristics, a compound item).

Each new layout is checked: its first record decoded this way must equal libasterix's
own decoding, else that layout always goes through libasterix. The tests compare both
paths on the conformance recording and on exported files.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix.characteristics import characteristics
from mhtrack.io.asterix.fill import announces
from mhtrack.io.asterix.notplots import flags048_item
from mhtrack.io.asterix.problems import Problems

#: Distinct encodings remembered per variable-size item (then libasterix parses each).
MAX_VARIANTS = 256
#: Record layouts (FSPECs) remembered.
MAX_LAYOUTS = 256


@dataclass(frozen=True)
class Field:
    """An element of a fixed-size item: bits ``[offset, offset + size)`` of the item's
    ``nbytes`` octets, ``value = raw × lsb`` (two's complement if ``signed``); ``lsb``
    ``None`` for a plain integer."""

    nbytes: int
    offset: int
    size: int
    lsb: float | None
    signed: bool

    def read(self, data: bytes, at: int) -> float | int:
        raw = int.from_bytes(data[at:at + self.nbytes], "big")
        raw = (raw >> (8 * self.nbytes - self.offset - self.size)) & ((1 << self.size) - 1)
        if self.signed and raw >> (self.size - 1):
            raw -= 1 << self.size
        return raw if self.lsb is None else raw * self.lsb


def field(record: Any, item: str, sub: str | None = None) -> Field:
    """The :class:`Field` of ``item`` (an element) or of its subitem ``sub`` (a group),
    from libasterix's spec classes."""
    base = _lib.modules()[0]
    var = record.cv_items_dict[item].cv_rule.cv_variation
    offset, element = 0, var
    if sub is not None:
        for cls, size in var.cv_items_list:
            nsp = getattr(cls, "cv_non_spare", None)
            if nsp is not None and nsp.cv_name == sub:
                element = nsp.cv_rule.cv_variation
                break
            offset += size
        else:
            raise KeyError(f"{item}/{sub}")
    if not issubclass(element, base.Element):
        raise TypeError(f"{item}/{sub} is not an element")
    content = element.cv_rule.cv_content
    lsb = getattr(content, "cv_lsb", None)
    signed = getattr(content, "cv_signedness", None) is base.Signed
    return Field(var.cv_bit_size // 8, offset, element.cv_bit_size,
                 None if lsb is None else float(lsb), signed)


@dataclass
class _Layout:
    fspec: bytes
    items: list[tuple[str, int | None]]  # name, size in octets (None: variable)
    ok: bool = True


class FastRecords:
    """Decodes the records of one category's blocks into rows, fast where it can:
    ``slow_row(record, at, problems)`` reads a libasterix record, ``fast_row(self, raw,
    spans, at, problems)`` the same row from the octets (``spans``: item -> (offset,
    length)); both give ``None`` for a record that is no row."""

    def __init__(self, spec: Any,
                 slow_row: Callable[[Any, int, Problems], tuple[Any, ...] | None],
                 fast_row: Callable[..., tuple[Any, ...] | None]) -> None:
        base, _ = _lib.modules()
        self.base = base
        self.record = spec.cv_record
        self.plot_row = slow_row
        self.fast_row = fast_row
        self.layouts: dict[bytes, list[_Layout]] = {}
        self.n_layouts = 0
        self.variants: dict[str, dict[bytes, Any]] = {}
        self.fixed = {name: isinstance(v := getattr(nsp.cv_rule, "cv_variation", None), type)
                      and issubclass(v, (base.Element, base.Group))
                      for name, nsp in self.record.cv_items_dict.items()}
        self.text: dict[tuple[str, bytes], Any] = {}
        self.fields: dict[str, Field] = {}
        self.sites: dict[int, tuple[float, float, float, int]] = {}

    def block(self, raw: bytes, at: int, problems: Problems) -> list[tuple[Any, ...]] | None:
        """Rows of one block's records, or ``None`` if they do not decode to exactly
        the block (libasterix's strict parsing); problems are counted only for a block
        that decodes."""
        rows: list[tuple[Any, ...]] = []
        local = Problems()
        p, n = 0, len(raw)
        while p < n:
            row_end = self._fast(raw, p, n, at, local)
            if row_end is None:
                row_end = self._slow(raw, p, at, local)
                if row_end is None:
                    return None
            row, p = row_end
            if row is not None:
                rows.append(row)
        for kind, count in local.counts.items():
            problems.add(kind, local.first[kind], count)
        return rows

    def _slow(self, raw: bytes, p: int, at: int, problems: Problems
              ) -> tuple[tuple[Any, ...] | None, int] | None:
        """One record by libasterix; learns its layout."""
        bits = self.base.Bits.from_bytes(raw[p:])
        result = self.record.parse(self.base.ParsingMode.StrictParsing, bits)
        if isinstance(result, ValueError):
            return None
        rec, rest = result
        end = len(raw) - len(rest) // 8
        row = self.plot_row(rec, at, problems)
        if not rec.items_rfs and self.n_layouts < MAX_LAYOUTS:
            self._learn(rec, raw, p, end, row)
        return row, end

    def _learn(self, rec: Any, raw: bytes, p: int, end: int, row: Any) -> None:
        items, size = [], 0
        for name, obj in rec.items_regular.items():
            k = len(obj.unparse()) // 8
            size += k
            items.append((name, k if self.fixed[name] else None))
        fspec = raw[p:end - size]
        if any(lay.fspec == fspec for lay in self.layouts.get(fspec[:1], ())):
            return  # known (a layout that failed its check stays off)
        layout = _Layout(fspec, items)
        self.layouts.setdefault(fspec[:1], []).append(layout)
        self.n_layouts += 1
        check = self._fast(raw, p, len(raw), 0, Problems(), only=layout)
        layout.ok = check is not None and check[1] == end and _same(check[0], row)

    def fills(self, raw: bytes) -> bool:
        """The records of ``raw`` (a block's octets after its header) follow one another
        to exactly its end: each record's length from a learnt layout, else from
        libasterix's strict parsing (nothing learnt, no row read); each record's FSPEC
        announces an item (:func:`~mhtrack.io.asterix.fill.announces`)."""
        p, n = 0, len(raw)
        while p < n:
            if not announces(raw, p):
                return False
            found = self._spans(raw, p, n)
            if found is None:
                bits = self.base.Bits.from_bytes(raw[p:])
                result = self.record.parse(self.base.ParsingMode.StrictParsing, bits)
                if isinstance(result, ValueError):
                    return False
                p = n - len(result[1]) // 8
            else:
                p = found[1]
        return True

    def _spans(self, raw: bytes, p: int, n: int, only: _Layout | None = None
               ) -> tuple[dict[str, tuple[int, int]], int] | None:
        """The items (name -> (offset, length)) and end of the record at ``p`` by a
        learnt layout, or ``None`` if none applies."""
        for layout in [only] if only is not None else self.layouts.get(raw[p:p + 1], ()):
            if (not layout.ok and only is None) or not raw.startswith(layout.fspec, p):
                continue
            q = p + len(layout.fspec)
            spans: dict[str, tuple[int, int]] = {}
            for name, size in layout.items:
                if size is None:
                    size = self._variable(name, raw, q)
                    if size is None:
                        return None
                spans[name] = (q, size)
                q += size
            return None if q > n else (spans, q)
        return None

    def _fast(self, raw: bytes, p: int, n: int, at: int, problems: Problems,
              only: _Layout | None = None) -> tuple[tuple[Any, ...] | None, int] | None:
        """One record through a learnt layout, or ``None`` if none applies."""
        found = self._spans(raw, p, n, only)
        if found is None:
            return None
        return self.fast_row(self, raw, found[0], at, problems), found[1]

    def _variable(self, name: str, raw: bytes, q: int) -> int | None:
        """Length of the variable-size item ``name`` at ``q``: a known encoding, or one
        libasterix parses now."""
        known = self.variants.setdefault(name, {})
        for enc in known:
            if raw.startswith(enc, q):
                return len(enc)
        nsp = self.record.cv_items_dict[name]
        result = nsp.parse(self.base.Bits.from_bytes(raw[q:]))
        if isinstance(result, ValueError):
            return None
        k = len(result[0].unparse()) // 8
        if len(known) < MAX_VARIANTS:
            known[raw[q:q + k]] = True
        return k

    def _decoded(self, name: str, enc: bytes, get: Callable[[Any], Any]) -> Any:
        key = (name, enc)
        if key not in self.text:
            obj = self.record.cv_items_dict[name].parse(self.base.Bits.from_bytes(enc))
            self.text[key] = get(obj[0])
        return self.text[key]


def cat048_row(self: FastRecords, raw: bytes, spans: dict[str, tuple[int, int]], at: int,
               problems: Problems) -> tuple[Any, ...] | None:
    """The same row as :func:`~mhtrack.io.asterix.decode.plot_row`."""
    f = self.fields
    if "040" not in spans:
        problems.add("no_position", at)
        return None
    if "010" not in spans or "140" not in spans:
        problems.add("no_time", at)
        return None
    sac, sic = f["sac"].read(raw, spans["010"][0]), f["sic"].read(raw, spans["010"][0])
    q = spans["040"][0]
    rho = f["rho"].read(raw, q) * 1852.0
    theta = f["theta"].read(raw, q)
    fl = f["fl"].read(raw, spans["090"][0]) if "090" in spans else float("nan")
    m3a = callsign = ""
    if "070" in spans:
        m3a = self._decoded("070", raw[slice(*_range(spans["070"]))], _mode_3a)
    if "240" in spans:
        callsign = self._decoded("240", raw[slice(*_range(spans["240"]))], _callsign)
    address = f"{f['address'].read(raw, spans['220'][0]):06X}" if "220" in spans else ""
    tn = f["trn"].read(raw, spans["161"][0]) if "161" in spans else -1
    flags = self._decoded("020", raw[slice(*_range(spans["020"]))], flags048_item) \
        if "020" in spans else (-1, -1, -1, -1)
    vg = [2 * f[f"{k}_v"].read(raw, spans[k][0]) + f[f"{k}_g"].read(raw, spans[k][0])
          if k in spans else 0 for k in ("070", "090")]
    char = self._decoded("130", raw[slice(*_range(spans["130"]))], characteristics) \
        if "130" in spans else ()
    return (f["tod"].read(raw, spans["140"][0]), sac * 256 + sic, sac, sic, rho, theta,
            fl, m3a, address, callsign, tn, *flags, *vg, *char)


def cat034_row(self: FastRecords, raw: bytes, spans: dict[str, tuple[int, int]], at: int,
               problems: Problems) -> tuple[Any, ...] | None:
    """The same mark as :func:`~mhtrack.io.asterix.decode.mark_row`."""
    f = self.fields
    if "010" in spans and "120" in spans:
        sensor = f["sac"].read(raw, spans["010"][0]) * 256 + f["sic"].read(raw,
                                                                          spans["010"][0])
        if sensor not in self.sites:
            q = spans["120"][0]
            self.sites[sensor] = (f["lat"].read(raw, q), f["lon"].read(raw, q),
                                  f["hgt"].read(raw, q), at)
    if "000" not in spans or "010" not in spans or "030" not in spans:
        return None
    kind = f["kind"].read(raw, spans["000"][0])
    if kind not in (1, 2):
        return None
    sac, sic = f["sac"].read(raw, spans["010"][0]), f["sic"].read(raw, spans["010"][0])
    azimuth = f["azimuth"].read(raw, spans["020"][0]) if "020" in spans and kind == 2 \
        else float("nan")
    period = f["period"].read(raw, spans["041"][0]) if "041" in spans else float("nan")
    return f["tod"].read(raw, spans["030"][0]), sac * 256 + sic, kind, azimuth, period


def reader048(slow_row: Callable[[Any, int, Problems], tuple[Any, ...] | None]
              ) -> FastRecords:
    """The fast reader of CAT048 plots."""
    r = _lib.cat048()
    out = FastRecords(r, slow_row, cat048_row)
    rec = r.cv_record
    out.fields = {
        "sac": field(rec, "010", "SAC"), "sic": field(rec, "010", "SIC"),
        "tod": field(rec, "140"), "rho": field(rec, "040", "RHO"),
        "theta": field(rec, "040", "THETA"), "fl": field(rec, "090", "FL"),
        "trn": field(rec, "161", "TRN"), "address": field(rec, "220"),
        "070_v": field(rec, "070", "V"), "070_g": field(rec, "070", "G"),
        "090_v": field(rec, "090", "V"), "090_g": field(rec, "090", "G"),
    }
    return out


def reader034(slow_row: Callable[[Any, int, Problems], tuple[Any, ...] | None],
              sites: dict[int, tuple[float, float, float, int]]) -> FastRecords:
    """The fast reader of CAT034 north markers and sector crossings; each radar's first
    I034/120 goes to ``sites`` (``sensor -> (lat, lon, height, byte offset)``), as
    ``slow_row`` puts it there for the records libasterix reads."""
    r = _lib.cat034()
    out = FastRecords(r, slow_row, cat034_row)
    out.sites = sites
    rec = r.cv_record
    out.fields = {
        "kind": field(rec, "000"), "sac": field(rec, "010", "SAC"),
        "sic": field(rec, "010", "SIC"), "tod": field(rec, "030"),
        "azimuth": field(rec, "020"), "period": field(rec, "041"),
        "lat": field(rec, "120", "LAT"), "lon": field(rec, "120", "LON"),
        "hgt": field(rec, "120", "HGT"),
    }
    return out


def _same(a: tuple[Any, ...] | None, b: tuple[Any, ...] | None) -> bool:
    """Rows equal, NaN equal to NaN."""
    if a is None or b is None:
        return a is b
    return len(a) == len(b) and all(x == y or (x != x and y != y) for x, y in
                                    zip(a, b, strict=True))


def _range(span: tuple[int, int]) -> tuple[int, int]:
    return span[0], span[0] + span[1]


def _mode_3a(item: Any) -> str:
    return str(item.variation.get_item("MODE3A").variation.content.as_string())


def _callsign(item: Any) -> str:
    return str(item.variation.content.as_string()).strip()


