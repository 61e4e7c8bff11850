"""ASTERIX records assembled with NumPy from fields of fixed size (EUROCONTROL ASTERIX
Part 1): values big-endian, two's complement where signed; an FSPEC (of a record, or
of a compound item's subfields) holds one bit per field reference number (FRN 1 the
top bit of its first octet, seven per octet) and, in the low bit of each octet, FX:
another octet follows. An FSPEC ends with its last octet that has a field (the shortest
form, as libasterix writes it).

A record is a list of :data:`Segment`: ``(present, octets)``, a row mask and an
``(n, k)`` array of octets; a row's record is its present segments' octets in order.
"""

from __future__ import annotations

import numpy as np

#: ``(rows that carry it, (n, k) octets)``.
Segment = tuple[np.ndarray, np.ndarray]


def big_endian(value: np.ndarray | int, size: int, n: int) -> np.ndarray:
    """``(n, size)`` octets of ``value`` big-endian, modulo 2^(8·size) (two's
    complement for negative values)."""
    v = np.broadcast_to(np.asarray(value, np.int64), (n,)) & ((1 << (8 * size)) - 1)
    shifts = np.arange(8 * (size - 1), -1, -8, dtype=np.int64)
    return ((v[:, None] >> shifts) & 0xFF).astype(np.uint8)


def fspec(fields: dict[int, np.ndarray], n: int) -> list[Segment]:
    """The FSPEC of rows with fields ``{FRN: present}``: octets up to the last one with
    a field, FX set on all but that one (module docstring)."""
    size = (max(fields) + 6) // 7
    bits = np.zeros((n, size), np.uint8)
    for frn, present in fields.items():
        bits[:, (frn - 1) // 7] |= np.asarray(present, np.uint8) << (7 - (frn - 1) % 7)
    nz = bits != 0
    last = np.where(nz.any(axis=1), size - 1 - np.argmax(nz[:, ::-1], axis=1), 0)
    octet = np.arange(size)
    bits |= (octet[None, :] < last[:, None]).astype(np.uint8)
    return [(octet[k] <= last, bits[:, k:k + 1]) for k in range(size)]


def compound(fields: dict[int, Segment], n: int) -> list[Segment]:
    """A compound item of subfields ``{FRN: (present, octets)}``: its FSPEC of the
    subfields present, then their octets; present on the rows with some subfield."""
    has = {k: np.asarray(p, bool) for k, (p, _) in fields.items()}
    some = np.logical_or.reduce(list(has.values()))
    return [(p & some, o) for p, o in fspec(has, n)] + [fields[k] for k in sorted(fields)]


def assemble(segments: list[Segment], order: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(octets of the records of rows `order`, one after the other; each record's
    length)``."""
    data = np.concatenate([o for _, o in segments], axis=1)[order]
    keep = np.concatenate([np.repeat(np.asarray(p, bool)[:, None], o.shape[1], axis=1)
                           for p, o in segments], axis=1)[order]
    return data[keep], keep.sum(axis=1)
