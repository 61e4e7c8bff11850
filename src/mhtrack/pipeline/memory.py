"""The process's memory as the system sees it, and giving freed memory back
(``docs/live.md``, *Soak*).

:func:`status_kb` reads ``VmRSS``, ``VmHWM`` and ``RssAnon`` of ``/proc/self/status``
(Linux; empty elsewhere). :func:`malloc_stats` is glibc's ``mallinfo2()`` summed over
its arenas (glibc ≥ 2.33; ``None`` elsewhere): ``arena`` bytes taken from the system
(``brk`` and per-thread heaps), ``uordblks`` of them in use, ``fordblks`` free inside
the arenas, ``hblkhd`` in separately mmapped chunks. :func:`malloc_trim` is glibc's
``malloc_trim(0)``: the free pages inside every arena are returned to the system
(``madvise(MADV_DONTNEED)``), not only the top of the main heap — what ``free`` does by
itself only above ``M_TRIM_THRESHOLD`` at the top of a heap.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import sys
from pathlib import Path

#: ``struct mallinfo2`` (glibc ≥ 2.33, ``malloc.h``): ten ``size_t`` fields.
_FIELDS = ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks",
           "uordblks", "fordblks", "keepcost")


class _Mallinfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in _FIELDS]


@functools.cache
def _libc() -> ctypes.CDLL | None:
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.malloc_trim.argtypes = [ctypes.c_size_t]
        libc.malloc_trim.restype = ctypes.c_int
    except (OSError, AttributeError):
        return None
    return libc


def status_kb() -> dict[str, int]:
    """``VmRSS``, ``VmHWM`` and ``RssAnon`` (kB) of this process (``{}`` without
    ``/proc``)."""
    try:
        text = Path("/proc/self/status").read_text()
    except OSError:
        return {}
    got = {}
    for line in text.splitlines():
        key, _, value = line.partition(":")
        if key in ("VmRSS", "VmHWM", "RssAnon"):
            got[key] = int(value.split()[0])
    return got


def malloc_stats() -> dict[str, int] | None:
    """glibc's ``mallinfo2()`` as a dict (module docstring); ``None`` without it."""
    libc = _libc()
    fn = getattr(libc, "mallinfo2", None)
    if fn is None:
        return None
    fn.restype = _Mallinfo2
    info = fn()
    return {name: int(getattr(info, name)) for name in _FIELDS}


def malloc_trim() -> bool | None:
    """glibc's ``malloc_trim(0)`` (module docstring): whether memory was returned;
    ``None`` without glibc."""
    libc = _libc()
    if libc is None or not hasattr(libc, "malloc_trim"):
        return None
    return bool(libc.malloc_trim(0))
