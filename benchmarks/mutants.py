"""Damaged recordings through ``convert`` and ``track`` (issue 33, acceptance run 1).

Usage: ``python benchmarks/mutants.py [--mutants 2000] [--seed 0] [--work DIR]
[--shard K/N] [--formats raw]``.

A small but rich recording (the ``opensky-radars`` preset, seed 1, its first 45 s: three
rotating radars, 1 129 plots, 190 CAT034 sweep marks) is exported as pcap, then written
again as pcapng and as raw data blocks from the same datagrams. Each mutant is one of
these three files with one seeded damage: bit flips (1–3 within 16 octets), a truncation,
inserted or deleted octets, a splice (a stretch replaced by octets from elsewhere in the
file), a packet duplicated elsewhere, or two packets swapped.

A **packet** is a pcap record (its 16-octet header and frame), a pcapng block, or a raw
data block; the file's own header (pcap global header, pcapng section header and
interface description) is the **header**. A packet is **touched** when the damage
changes one of its octets (an insertion strictly inside it counts; one at a packet
boundary touches none); swapped and duplicated packets are whole, so untouched. The
plots of a packet are those the decoder takes from the original file's packet. For each
mutant:

* ``convert`` and ``track`` (with the sensors file) end with status 0, or with status 2
  (a one-line refusal) only when the damage touched the header or no untouched packet
  holds a plot; status 1 (a traceback) or more than ``--timeout`` s (a hang) never;
* every plot of every untouched packet is in ``convert``'s output (sensor, slant range,
  bearing, time of day compared exactly; a multiset, so that a duplicate hides nothing).

The plots ``track`` decodes (:class:`~mhtrack.sources.recording.AsterixSource`, its
decoding stage: the plots and skip lines before conversion) are compared with
``convert``'s (``read_recording``): **paths differ** counts the mutants where the two
readings give other plots or other skip lines, and the track path's own plots lost and
garbage are counted as ``convert``'s are.

Also counted, not failures: **garbage** plots (in ``convert``'s output, not in the
original recording at all: damaged octets that still decode as valid ASTERIX) and the
raw blocks lost inside a damaged length (``raw-covered``, documented).

Prints the counts per format and per kind of damage (tracebacks, hangs, refusals,
mutants losing plots of untouched packets and the plots lost, garbage), and the failures
(each with its seed so that it can be replayed: ``--only FORMAT-KIND-SEED``).
``--no-track`` runs ``convert`` alone. Exit status 1 when any check failed.
"""

from __future__ import annotations

import argparse
import collections
import random
import signal
import struct
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow.csv as pacsv
from click.testing import CliRunner

from mhtrack.cli.main import cli
from mhtrack.io.asterix import wrap
from mhtrack.io.asterix.decode import PLOT_COLUMNS, Decoder
from mhtrack.io.asterix.framings import recognise, units
from mhtrack.io.asterix.problems import Problems

KINDS = ("bitflip", "truncate", "insert", "delete", "splice", "duplicate", "swap")
FORMATS = ("pcap", "pcapng", "raw")
#: The key of a plot: (sensor, slant range, bearing, time of day); the time of day, not
#: the time axis, since damage to a capture time may legitimately move the axis.
KEY = ("sensor", "slant_range", "bearing")


@dataclass
class Base:
    """One undamaged recording: its octets, each packet's span, the header's span, and
    the plot keys of each packet."""

    fmt: str
    data: bytes
    spans: list[tuple[int, int]]
    header: tuple[int, int]
    plots: list[list[tuple[float, ...]]]


def _invoke(args: list[str], timeout: float) -> tuple[int, str]:
    """Run one ``mhtrack`` command in this process: ``(status, output)``; status 1 with
    the traceback for an exception, 124 for a hang (``timeout`` s)."""
    def hang(signum: int, frame: object) -> None:
        raise TimeoutError(f"no result after {timeout} s")

    old = signal.signal(signal.SIGALRM, hang)
    signal.setitimer(signal.ITIMER_REAL, timeout)
    try:
        res = CliRunner().invoke(cli, args, catch_exceptions=True)
    except TimeoutError as e:
        return 124, str(e)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    if isinstance(res.exception, TimeoutError):
        return 124, str(res.exception)
    if res.exit_code not in (0, 2) or (res.exception is not None
                                       and not isinstance(res.exception, SystemExit)):
        import traceback

        tb = "".join(traceback.format_exception(*res.exc_info)) if res.exc_info else ""
        return 1, res.output + tb
    return res.exit_code, res.output


def _pcap_spans(data: bytes) -> list[tuple[int, int]]:
    out, p = [], 24
    while p < len(data):
        caplen = struct.unpack_from("<I", data, p + 8)[0]
        out.append((p, p + 16 + caplen))
        p += 16 + caplen
    return out


def _pcapng_spans(data: bytes) -> list[tuple[int, int]]:
    out, p = [], 0
    while p < len(data):
        length = struct.unpack_from("<I", data, p + 4)[0]
        out.append((p, p + length))
        p += length
    return out


def _raw_spans(data: bytes) -> list[tuple[int, int]]:
    out, p = [], 0
    while p < len(data):
        length = (data[p + 1] << 8) | data[p + 2]
        out.append((p, p + length))
        p += length
    return out


def _plots_by_packet(data: bytes, spans: list[tuple[int, int]]
                     ) -> list[list[tuple[float, ...]]]:
    """Each packet's plot keys, from the decoder run on the undamaged file."""
    decoder = Decoder()
    problems = Problems()
    kind = recognise(data, "base", decoder.categories)
    starts = np.array([s for s, _ in spans])
    out: list[list[tuple[float, ...]]] = [[] for _ in spans]
    idx = [PLOT_COLUMNS.index(k) for k in KEY]
    for offset, when, payload in units(data, kind, "base", decoder.categories, problems):
        for at, what, found in decoder.blocks(payload, offset, problems, when):
            if what == "plots":
                i = int(np.searchsorted(starts, at, side="right")) - 1
                out[i].extend((*(float(r[j]) for j in idx), float(r[0]) % 86400)
                              for r in found)
    assert not problems.counts, problems.counts  # the base is undamaged
    return out


def make_bases(work: Path) -> tuple[dict[str, Base], Path]:
    """The three undamaged recordings and the sensors file."""
    res = CliRunner().invoke(cli, ["simulate", "opensky-radars", "--seed", "1", "--scans",
                                   "12", "--out", str(work / "sim")])
    assert res.exit_code == 0, res.output
    table = pacsv.read_csv(work / "sim" / "plots.csv")
    import pyarrow.compute as pc

    pacsv.write_csv(table.filter(pc.less(table["time"], 45.0)), work / "plots.csv")
    sensors = work / "sim" / "sensors.toml"
    res = CliRunner().invoke(cli, ["export", str(work / "plots.csv"), "--sensors",
                                   str(sensors), "--out", str(work / "base.pcap")])
    assert res.exit_code == 0, res.output
    pcap = (work / "base.pcap").read_bytes()
    spans = _pcap_spans(pcap)
    frames = [pcap[s + 16:e] for s, e in spans]
    times = [struct.unpack_from("<II", pcap, s) for s, _ in spans]
    seconds = [a + b * 1e-6 for a, b in times]
    pcapng = wrap.pcapng(frames, seconds)
    raw = b"".join(f[42:] for f in frames)  # Ethernet, IPv4, UDP headers: 42 octets
    bases = {}
    for fmt, data, spans_of, header in (
            ("pcap", pcap, _pcap_spans, 24),
            ("pcapng", pcapng, _pcapng_spans, None),
            ("raw", raw, _raw_spans, 0)):
        sp = spans_of(data)
        if header is None:  # section header and interface description blocks
            header, sp = sp[1][1], sp[2:]
        bases[fmt] = Base(fmt, data, sp, (0, header), _plots_by_packet(data, sp))
    return bases, sensors


Mutant = tuple[bytes, set[int], bool, tuple[int, int, int] | None]


def mutate(base: Base, rng: random.Random, kind: str) -> Mutant:
    """``(damaged octets, indices of touched packets, header touched, region)``; region
    ``(a, b, m)``: the original's octets ``[a, b)`` replaced by ``m`` others (``None``
    for the packet-level damages)."""
    data, n = base.data, len(base.data)
    spans = base.spans

    def region(a: int, b: int, new: bytes) -> Mutant:
        if a == b:  # an insertion: touches the packet it falls strictly inside
            hit = {i for i, (s, e) in enumerate(spans) if s < a < e}
            head = base.header[0] < a < base.header[1]
        else:
            hit = {i for i, (s, e) in enumerate(spans) if s < b and a < e}
            head = base.header[0] < b and a < base.header[1]
        return data[:a] + new + data[b:], hit, head, (a, b, len(new))

    if kind == "bitflip":
        a = rng.randrange(n)
        flips = [min(n - 1, a + rng.randrange(16)) for _ in range(rng.randint(1, 3))]
        out = bytearray(data)
        for p in flips:
            out[p] ^= 1 << rng.randrange(8)
        lo, hi = min(flips), max(flips) + 1
        return region(lo, hi, bytes(out[lo:hi]))
    if kind == "truncate":
        a = rng.randrange(base.header[1], n)
        return region(a, n, b"")
    if kind == "insert":
        a = rng.randrange(n + 1)
        return region(a, a, rng.randbytes(rng.randint(1, 64)))
    if kind == "delete":
        a = rng.randrange(n)
        return region(a, min(n, a + rng.randint(1, 64)), b"")
    if kind == "splice":
        a = rng.randrange(n)
        b = min(n, a + rng.randint(1, 200))
        c = rng.randrange(n)
        return region(a, b, data[c:c + rng.randint(1, 200)])
    i = rng.randrange(len(spans) - 1)
    s, e = spans[i]
    if kind == "duplicate":  # a copy of packet i after packet j (a re-sent packet)
        j = min(len(spans) - 1, i + rng.randint(0, 20))
        at = spans[j][1]
        return data[:at] + data[s:e] + data[at:], set(), False, None
    t, u = spans[i + 1]  # swap packets i and i + 1
    return data[:s] + data[t:u] + data[s:e] + data[u:], set(), False, None


def covered(base: Base, damaged: bytes, touched: set[int],
            region: tuple[int, int, int] | None) -> set[int]:
    """Raw data blocks have no framing of their own: the untouched blocks that lie
    inside the length claimed by a block header read in the damaged stretch (the
    touched blocks, in the damaged file), which ``docs/file-formats.md`` says such a
    length may take with it."""
    if base.fmt != "raw" or region is None or not touched:
        return set()
    a, b, m = region
    delta = m - (b - a)

    def moved(s: int) -> int:
        return s if s < a else s + delta

    lo = min(base.spans[i][0] for i in touched)
    hi = max(base.spans[i][1] for i in touched) + delta
    cats = Decoder().categories
    out: set[int] = set()
    n = len(damaged)
    for q in range(lo, min(hi, n - 2)):
        length = (damaged[q + 1] << 8) | damaged[q + 2]
        if damaged[q] in cats and length >= 3 and q + length <= n:
            out |= {i for i, (s, e) in enumerate(base.spans) if i not in touched
                    and q < moved(s) and moved(e) <= q + length and (e <= a or s >= b)}
    return out


@dataclass
class Outcome:
    """What one mutant did: commands ending in a traceback or a hang, refusals of a
    recording that still holds plots, plots of untouched packets lost (``covered``: all
    of them inside a damaged raw length, documented), plots ``convert`` wrote that the
    original does not hold (garbage: damaged octets that decode as valid ASTERIX), and a
    line per failure."""

    tracebacks: int = 0
    hangs: int = 0
    refusals: int = 0
    lost: int = 0
    covered: bool = False
    garbage: int = 0
    differ: bool = False
    track_lost: int = 0
    track_garbage: int = 0
    fails: list[str] = field(default_factory=list)


def _run(outcome: Outcome, what: str, args: list[str], may_refuse: bool,
         timeout: float) -> int:
    status, text = _invoke(args, timeout)
    if status not in (0, 2) or (status == 2 and not may_refuse):
        outcome.tracebacks += status == 1
        outcome.hangs += status == 124
        outcome.refusals += status == 2
        outcome.fails.append(f"{what} status {status}: {text.strip()[-400:]}")
    return status


def check(base: Base, sensors: Path, work: Path, seed: int, kind: str, timeout: float,
          track: bool = True) -> Outcome:
    """What one mutant did (:class:`Outcome`; no ``fails``: it passed)."""
    rng = random.Random(f"{base.fmt}-{kind}-{seed}")
    damaged, touched, head, region = mutate(base, rng, kind)
    excused = covered(base, damaged, touched, region)
    ext = {"pcap": ".pcap", "pcapng": ".pcapng", "raw": ".ast"}[base.fmt]
    path = work / f"m{ext}"
    path.write_bytes(damaged)
    kept = [k for i, keys in enumerate(base.plots) if i not in touched for k in keys]
    may_refuse = head or not kept
    res = Outcome()
    out = work / "c.csv"
    out.unlink(missing_ok=True)
    status = _run(res, "convert", ["convert", str(path), str(out)], may_refuse, timeout)
    if status == 0 and not head:
        t = pacsv.read_csv(out).to_pydict()
        got = collections.Counter(zip(*(map(float, t[k]) for k in KEY),
                                      (float(x) % 86400 for x in t["time"]), strict=True))
        known = {k for keys in base.plots for k in keys}
        res.garbage = sum(c for k, c in got.items() if k not in known)
        missing = collections.Counter(kept) - got
        also = collections.Counter(k for i in excused for k in base.plots[i])
        res.lost = sum(missing.values())
        if missing and not missing - also:
            res.covered = True
        elif missing:
            res.fails.append(f"convert lost {res.lost} plot(s) of untouched packets, e.g. "
                             f"{next(iter(missing))}")
    if track:
        _compare_paths(res, path, kept, {k for keys in base.plots for k in keys})
        _run(res, "track", ["track", str(path), "--sensors", str(sensors), "--out",
                            str(work / "t.csv")], may_refuse, timeout)
    return res


def _keys(plots: dict[str, np.ndarray]) -> collections.Counter[tuple[float, ...]]:
    """The plot keys (:data:`KEY`, then the time of day) of decoded plot columns."""
    return collections.Counter(zip(*(map(float, plots[k]) for k in KEY),
                                   (float(x) % 86400 for x in plots["time"]), strict=True))


def _compare_paths(res: Outcome, path: Path, kept: list[tuple[float, ...]],
                   known: set[tuple[float, ...]]) -> None:
    """The plots and skip lines of ``track``'s reading (the source's decoding stage)
    against ``convert``'s (``read_recording``); the track path's plots of untouched
    packets lost, and its garbage."""
    from mhtrack.errors import InputError
    from mhtrack.io.asterix.decode import read_recording
    from mhtrack.sources.recording import AsterixSource

    try:
        rec = read_recording(path)
    except InputError as e:
        rec, refused = None, str(e)
    try:
        src = AsterixSource(path)
    except InputError as e:
        res.differ = rec is not None or str(e) != refused
        return
    if rec is None:
        res.differ = True
        return
    problems = Problems()
    chunks = list(src._decoded(problems, convert=False))
    cols = {k: np.concatenate([c[k] for c in chunks]) if chunks else np.zeros(0)
            for k in (*KEY, "time")}
    got = _keys(cols)
    res.differ = got != _keys(rec.plots) or problems.lines(str(path)) != \
        rec.problems.lines(str(path))
    res.track_lost = sum((collections.Counter(kept) - got).values())
    res.track_garbage = sum(c for k, c in got.items() if k not in known)


def _tables(columns: tuple[str, ...], counts: dict[tuple[str, str], list[int]],
            detail: bool = True) -> None:
    """The counts per format (and, with ``detail``, per format and damage)."""
    head = f"{'format':8} {'damage':10} " + " ".join(f"{c:>{max(7, len(c))}}"
                                                    for c in columns)
    for title, key in (("per format and damage", lambda fk: fk),
                       ("per format", lambda fk: (fk[0], "all")))[0 if detail else 1:]:
        table: dict[tuple[str, str], list[int]] = collections.defaultdict(
            lambda: [0] * len(columns))
        for fk, row in counts.items():
            table[key(fk)] = [a + b for a, b in zip(table[key(fk)], row, strict=True)]
        print(f"\n{title}\n{head}")
        for (fmt, kind), row in sorted(table.items()):
            print(f"{fmt:8} {kind:10} " + " ".join(
                f"{v:>{max(7, len(c))}d}" for c, v in zip(columns, row, strict=True)))
    sys.stdout.flush()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mutants", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--only", help="replay one mutant: FORMAT-KIND-SEED")
    ap.add_argument("--work", type=Path, default=None)
    ap.add_argument("--shard", default="0/1", help="K/N: run the mutants K, K + N, ...")
    ap.add_argument("--formats", default=",".join(FORMATS),
                    help="only these formats' mutants (the same seeds as in the full run)")
    ap.add_argument("--every", type=int, default=200,
                    help="print the counts so far every this many mutants")
    ap.add_argument("--no-track", action="store_true",
                    help="run convert only (the plots lost and the garbage)")
    args = ap.parse_args(argv)
    work = args.work or Path(tempfile.mkdtemp(prefix="mutants-"))
    work.mkdir(parents=True, exist_ok=True)
    bases, sensors = make_bases(work)
    print(", ".join(f"{f}: {len(b.data)} octets, {len(b.spans)} packets, "
                    f"{sum(map(len, b.plots))} plots" for f, b in bases.items()))
    jobs: list[tuple[str, str, int]] = []
    if args.only:
        fmt, kind, seed = args.only.rsplit("-", 2)
        jobs = [(fmt, kind, int(seed))]
    else:
        rng = random.Random(args.seed)
        jobs = [(rng.choice(FORMATS), rng.choice(KINDS), rng.randrange(2**31))
                for _ in range(args.mutants)]
        k, n = map(int, args.shard.split("/"))
        jobs = [j for j in jobs[k::n] if j[0] in args.formats.split(",")]
    columns = ("mutants", "failed", "tracebacks", "hangs", "refusals", "losing",
               "plots lost", "raw-covered", "garbage", "garbage plots", "paths differ",
               "track losing", "track lost", "track garbage")
    counts: dict[tuple[str, str], list[int]] = collections.defaultdict(
        lambda: [0] * len(columns))
    failures: list[str] = []
    for i, (fmt, kind, seed) in enumerate(jobs, 1):
        o = check(bases[fmt], sensors, work, seed, kind, args.timeout, not args.no_track)
        losing = o.lost > 0 and not o.covered
        for j, v in enumerate((1, bool(o.fails), o.tracebacks, o.hangs, o.refusals,
                               losing, o.lost if losing else 0, o.covered,
                               o.garbage > 0, o.garbage, o.differ, o.track_lost > 0,
                               o.track_lost, o.track_garbage)):
            counts[fmt, kind][j] += int(v)
        if o.fails:
            failures.append(f"{fmt}-{kind}-{seed}: " + " | ".join(o.fails))
            print("FAIL", failures[-1], flush=True)
        if i % args.every == 0:
            print(f"  {i} mutants, {len(failures)} failed", flush=True)
            _tables(columns, counts, detail=False)
    _tables(columns, counts)
    total = sum(c[0] for c in counts.values())
    print(f"mutants: {total}, failed: {len(failures)}, raw blocks lost to a damaged "
          f"length (documented): {sum(c[7] for c in counts.values())}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
