"""Same outputs before and after a change (issue 18: "no behaviour change").

Not a speed figure: the check that goes with every speed change. ``run`` reruns the
acceptance commands with the library at ``SRC`` (``PYTHONPATH``) into ``OUT``; ``compare``
compares two such directories file by file, ignoring only timing fields (keys such as
``t_avg``, ``time_s``, ``seconds``, ``wall``; lines of reports that print times)::

    python benchmarks/identity.py run /tmp/base/src /tmp/before   # e.g. a git worktree
    python benchmarks/identity.py run src /tmp/after
    python benchmarks/identity.py compare /tmp/before /tmp/after  # "differences: 0"

The commands: ``run crossing|opensky|multiradar|crossing-changing --seed 1 --json``,
``montecarlo crossing --runs 5``, ``reproduce p2 --runs 2`` and the whole
``opensky-radars`` simulate → track → evaluate (its ``tracks.csv`` compared byte for byte),
and the same plots exported as an ASTERIX recording, tracked from it (history and online)
and the tracks exported as CAT062 (each file compared byte for byte).
"""

from __future__ import annotations

import argparse
import filecmp
import json
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

COMMANDS: list[tuple[str, list[str]]] = [
    *[(f"{p}.json", ["run", p, "--seed", "1", "--json", "--out", f"b_{p}"])
      for p in ("crossing", "opensky", "multiradar", "crossing-changing")],
    ("mc.txt", ["montecarlo", "crossing", "--runs", "5", "--out", "b_mc"]),
    ("p2.txt", ["reproduce", "p2", "--runs", "2", "--out", "b_p2"]),
    ("", ["simulate", "opensky-radars", "--seed", "1", "--out", "b_or"]),
    ("", ["track", "b_or/plots.csv", "--sensors", "b_or/sensors.toml", "--out",
          "b_or/tracks.csv"]),
    ("or_eval.json", ["evaluate", "b_or/tracks.csv", "b_or/truth.csv", "--json"]),
    ("", ["track", "b_or/plots.csv", "--sensors", "b_or/sensors.toml", "--output", "online",
          "--out", "b_or/tracks_online.csv"]),
    ("", ["export", "b_or/plots.csv", "--sensors", "b_or/sensors.toml", "--out",
          "b_or/radar.pcap"]),
    ("", ["track", "b_or/radar.pcap", "--sensors", "b_or/sensors.toml", "--out",
          "b_or/tracks_rec.csv"]),
    ("", ["track", "b_or/radar.pcap", "--sensors", "b_or/sensors.toml", "--output", "online",
          "--out", "b_or/tracks_rec_online.parquet"]),
    ("", ["export", "b_or/tracks_rec.csv", "--sensors", "b_or/sensors.toml", "--category",
          "062", "--out", "b_or/tracks_rec062.ast"]),
]

#: Keys of JSON objects and Parquet rows that hold times (ignored).
TIME_KEY = re.compile(r"^(t_|time)|_time$|_s$|seconds|wall|^at$")
#: Lines of text outputs that print times (ignored).
TIME_LINE = re.compile(r"\d ms|[Ww]all time|t_avg|[Tt]ime ratio|Ratios to|jobs computed"
                       r"|t_scan|t_window|time_s")


def run(src: str, out: Path) -> None:
    """Rerun :data:`COMMANDS` with ``PYTHONPATH=src`` in ``out`` (each command's stdout to
    the file named beside it)."""
    out.mkdir(parents=True, exist_ok=False)
    env = {**os.environ, "PYTHONPATH": str(Path(src).resolve())}
    cli = [sys.executable, "-c", "from mhtrack.cli.main import main; main()"]
    for i, (stdout, args) in enumerate(COMMANDS, 1):
        print(f"[{i}/{len(COMMANDS)}] mhtrack {' '.join(args)}", flush=True)
        with open(out / stdout if stdout else os.devnull, "w") as f:
            subprocess.run(cli + args, cwd=out, env=env, stdout=f,
                           stderr=subprocess.DEVNULL, check=False)


def strip(o: Any) -> Any:
    """``o`` without the timing keys, recursively."""
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if not TIME_KEY.search(str(k))}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o


def _json(p: Path) -> Any:
    text = p.read_text()
    try:
        return strip(json.loads(text))
    except json.JSONDecodeError:  # JSON lines
        return [strip(json.loads(line)) for line in text.splitlines() if line.strip()]


def same(a: Path, b: Path) -> bool:
    """Whether two output files agree, timing aside."""
    if a.suffix == ".json":
        return _json(a) == _json(b)
    if a.suffix in (".md", ".txt"):
        lines = [[ln for ln in p.read_text().splitlines() if not TIME_LINE.search(ln)]
                 for p in (a, b)]
        return lines[0] == lines[1]
    if a.suffix == ".toml":  # compared as data: the writer's layout may change
        import tomllib

        return tomllib.loads(a.read_text()) == tomllib.loads(b.read_text())
    if a.suffix == ".parquet":
        import pyarrow.parquet as pq

        return strip(pq.read_table(a).to_pylist()) == strip(pq.read_table(b).to_pylist())
    return filecmp.cmp(a, b, shallow=False)


def compare(base: Path, new: Path) -> int:
    """Print each file of ``base`` that is missing from or differs in ``new``; return
    their number (figures are not compared)."""
    bad = 0
    for f in sorted(p for p in base.rglob("*") if p.is_file() and p.suffix != ".png"):
        g = new / f.relative_to(base)
        if not g.exists() or not same(f, g):
            print("MISSING" if not g.exists() else "DIFF", f.relative_to(base))
            bad += 1
    print("checked; differences:", bad)
    return bad


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="rerun the acceptance commands")
    r.add_argument("src", help="the library's src directory (PYTHONPATH)")
    r.add_argument("out", type=Path, help="a new directory for the outputs")
    c = sub.add_parser("compare", help="compare two output directories")
    c.add_argument("base", type=Path)
    c.add_argument("new", type=Path)
    a = ap.parse_args()
    if a.cmd == "run":
        run(a.src, a.out)
    else:
        sys.exit(1 if compare(a.base, a.new) else 0)


if __name__ == "__main__":
    main()
