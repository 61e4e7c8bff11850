"""Where a running ``mhtrack`` process's memory is: runs the CLI in this process with a
watcher thread that, for each file ``req-TAG`` put in ``--dir``, writes ``probe-TAG.json``
(``benchmarks/soak.py --probe``; ``docs/live.md``, *Soak*):

* ``VmRSS``/``VmHWM``/``RssAnon`` (``/proc/self/status``) and the RSS of the mappings
  by kind (``/proc/self/smaps``: ``[heap]`` — glibc's main arena —, anonymous mappings
  of 64 MiB reservations — glibc's per-thread arenas —, the other anonymous ones —
  pymalloc's 1 MiB arenas, NumPy's large buffers —, files);
* glibc's ``mallinfo2()`` summed over its arenas: bytes from the system (``arena``),
  in use (``uordblks``), free inside the arenas (``fordblks``), mmapped (``hblkhd``);
* with ``--trace N``: ``tracemalloc``'s traced bytes (every Python allocation, objects
  and NumPy buffers alike) and the top lines, and the growth since the last probe;
* a request named ``req-TAG-trim`` then calls ``malloc_trim(0)`` and adds the RSS after
  it: what the allocator held free and now gave back.

    python benchmarks/memprobe.py --dir D [--trace 1] -- live --listen … (CLI arguments)
"""

from __future__ import annotations

import argparse
import ctypes
import ctypes.util
import functools
import json
import sys
import threading
import time
import tracemalloc
from pathlib import Path

ARENA = 64 << 20  # glibc's HEAP_MAX_SIZE on 64-bit: a thread arena's reservation

# -- the process's memory as the system sees it (was mhtrack.pipeline.memory, used only
# here): ``VmRSS``, ``VmHWM``, ``RssAnon`` of /proc/self/status (Linux; empty elsewhere);
# glibc's ``mallinfo2()`` summed over its arenas (glibc >= 2.33; None elsewhere):
# ``arena`` bytes taken from the system (brk and per-thread heaps), ``uordblks`` of them in
# use, ``fordblks`` free inside the arenas, ``hblkhd`` in separately mmapped chunks; and
# glibc's ``malloc_trim(0)``: the free pages inside every arena returned to the system
# (madvise(MADV_DONTNEED)), not only the top of the main heap — what ``free`` does by
# itself only above M_TRIM_THRESHOLD at the top of a heap.

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



def mappings() -> list[tuple[int, int, str, str, int]]:
    """``(start, end, perms, name, rss kB)`` of every mapping (``/proc/self/smaps``)."""
    out: list[list] = []
    with open("/proc/self/smaps") as fh:
        for line in fh:
            head = line.split()
            if "-" in head[0] and not head[0].endswith(":"):
                lo, hi = (int(v, 16) for v in head[0].split("-"))
                out.append([lo, hi, head[1], head[5] if len(head) > 5 else "", 0])
            elif head[0] == "Rss:":
                out[-1][4] = int(head[1])
    return [tuple(m) for m in out]


def smaps_kinds() -> dict[str, int]:
    """RSS (kB) of the mappings by kind (module docstring): ``heap`` (glibc's main
    arena), ``thread_arenas`` (anonymous mappings at a 64 MiB boundary whose
    reservation, with the inaccessible rest after them, is 64 MiB: glibc's per-thread
    arenas), ``anon`` (the other anonymous mappings: pymalloc's arenas, large NumPy
    buffers, thread stacks), ``file``."""
    out = {"heap": 0, "thread_arenas": 0, "anon": 0, "file": 0}
    maps = mappings()
    for i, (lo, hi, _perms, name, rss) in enumerate(maps):
        if name == "[heap]":
            out["heap"] += rss
        elif name and not name.startswith("["):
            out["file"] += rss
        elif lo % ARENA == 0 and (hi - lo == ARENA or (
                i + 1 < len(maps) and maps[i + 1][0] == hi and maps[i + 1][2] == "---p"
                and maps[i + 1][1] - lo == ARENA)):
            out["thread_arenas"] += rss
        else:
            out["anon"] += rss
    return out


def arena_sizes() -> list[tuple[int, int]]:
    """``(size kB, rss kB)`` of the anonymous mappings of 1 MiB or more, largest RSS
    first (the first 12)."""
    rows = [((hi - lo) >> 10, rss) for lo, hi, _, name, rss in mappings()
            if not name and hi - lo >= 1 << 20]
    return sorted(rows, key=lambda r: -r[1])[:12]


def _compiled_loaded() -> bool:
    """Whether the compiled IMM rows (``mhtrack.models.imm_rows``, numba) are loaded."""
    rows = sys.modules.get("mhtrack.models.imm_rows")
    return bool(rows is not None and getattr(rows, "_KERNELS", None))


class Prober:
    """The watcher (module docstring)."""

    def __init__(self, d: Path, frames: int) -> None:
        self.d, self.frames, self.last = d, frames, None
        self.modules: set[str] = set()

    def probe(self, tag: str, trim: bool) -> dict:
        got: dict = {"tag": tag, "time": time.time(), "status_kB": status_kb(),
                     "smaps_kB": smaps_kinds(), "anon_maps_kB": arena_sizes(),
                     "mallinfo2": malloc_stats(), "modules": len(sys.modules),
                     "numba": "numba" in sys.modules,
                     "compiled_rows": _compiled_loaded()}
        now = set(sys.modules)
        got["new_modules"] = sorted(now - self.modules)
        self.modules = now
        if self.frames:
            snap = tracemalloc.take_snapshot()
            cur, peak = tracemalloc.get_traced_memory()
            got["traced_MB"] = cur / 2**20
            got["traced_peak_MB"] = peak / 2**20
            stats = {str(s.traceback): (s.size, s.count) for s in snap.statistics("lineno")}
            del snap  # not kept: it would be most of the next probe's growth
            got["top"] = [(k, v[0] >> 10, v[1]) for k, v in sorted(
                stats.items(), key=lambda kv: -kv[1][0])[:15]]
            if self.last is not None:
                diff = {k: (v[0] - self.last.get(k, (0, 0))[0],
                            v[1] - self.last.get(k, (0, 0))[1]) for k, v in stats.items()}
                got["growth"] = [(k, v[0] >> 10, v[1]) for k, v in sorted(
                    diff.items(), key=lambda kv: -abs(kv[1][0]))[:15]]
            self.last = stats
        if trim:
            t0 = time.perf_counter()
            got["trim_returned"] = malloc_trim()
            got["trim_s"] = time.perf_counter() - t0
            got["after_trim_status_kB"] = status_kb()
            got["after_trim_mallinfo2"] = malloc_stats()
            got["after_trim_smaps_kB"] = smaps_kinds()
        return got

    def watch(self) -> None:
        while True:
            for req in sorted(self.d.glob("req-*")):
                tag = req.name[4:]
                got = self.probe(tag, tag.endswith("-trim"))
                tmp = self.d / f".probe-{tag}.json"
                tmp.write_text(json.dumps(got, indent=1))
                tmp.replace(self.d / f"probe-{tag}.json")
                req.unlink()
            time.sleep(0.2)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", type=Path, required=True)
    ap.add_argument("--trace", type=int, default=0, help="tracemalloc frames (0: off)")
    ap.add_argument("cli", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    if a.trace:
        tracemalloc.start(a.trace)
    a.dir.mkdir(parents=True, exist_ok=True)
    threading.Thread(target=Prober(a.dir, a.trace).watch, daemon=True,
                     name="memprobe").start()
    args = a.cli[1:] if a.cli[:1] == ["--"] else a.cli
    sys.argv = ["mhtrack", *args]
    from mhtrack.cli.main import main as cli_main
    cli_main()


if __name__ == "__main__":
    main()
