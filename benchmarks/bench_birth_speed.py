"""Time per frame of each ``--birth`` on ``opensky-radars`` (timed plots of three rotating
radars), every birth beside ``every-plot`` measured in the same run::

    mhtrack simulate opensky-radars --seed S --no-attributes --out D
    mhtrack track D/plots.csv --sensors D/sensors.toml --birth B --out D/t.csv

Each track runs in a fresh subprocess (the births in turn, ``--repeat`` rounds; medians
over rounds), timed inside it: the birth's ``propose`` (the initiator's whole per-frame
work: store, window, initiator, scores) and the tracker's ``step`` (the whole frame), both
in ms per frame. With ``--previous SRC`` the library at ``SRC`` (e.g. a ``git worktree``
of ``main``'s ``src``) runs in the same rounds, before ours, for a before/after figure.
Run: ``PYTHONPATH=src python benchmarks/bench_birth_speed.py [--seed 1] [--repeat 3]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

BIRTHS = ("every-plot", "logic", "modified-logic", "hough", "modified-hough")

#: Runs ``mhtrack track`` with the births' ``propose`` and the tracker's ``step`` timed;
#: prints one JSON line of seconds and counts.
CHILD = r"""
import json, sys, time
from mhtrack.mht.births.every_plot import EveryPlotBirth
from mhtrack.mht.births.initiator import InitiatorBirth
from mhtrack.mht.tracker import MHTTracker
acc = {"propose": 0.0, "step": 0.0, "frames": 0}
def timed(cls, name, key, count=False):
    f = getattr(cls, name)
    def g(*a, **k):
        t0 = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            acc[key] += time.perf_counter() - t0
            acc["frames"] += count
    setattr(cls, name, g)
timed(EveryPlotBirth, "propose", "propose")
timed(InitiatorBirth, "propose", "propose")
timed(MHTTracker, "step", "step", True)
from mhtrack.cli.main import main
sys.argv = ["mhtrack", *sys.argv[1:]]
try:
    main()
except SystemExit as e:
    if e.code not in (0, None):
        raise
print(json.dumps(acc))
"""


def run_track(src: str, d: Path, birth: str) -> dict[str, float]:
    """One ``mhtrack track`` of ``d``'s plots with ``--birth birth``, library at ``src``."""
    env = {**os.environ, "PYTHONPATH": str(Path(src).resolve())}
    out = subprocess.run(
        [sys.executable, "-c", CHILD, "track", str(d / "plots.csv"), "--sensors",
         str(d / "sensors.toml"), "--birth", birth, "--out", str(d / f"t_{birth}.csv")],
        capture_output=True, text=True, check=True, env=env).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--births", default=",".join(BIRTHS))
    ap.add_argument("--src", default="src", help="the library measured (default: src)")
    ap.add_argument("--previous", default=None, help="another library's src, run alongside")
    a = ap.parse_args(argv)
    births = a.births.split(",")
    if "every-plot" not in births:
        births.insert(0, "every-plot")
    libs = ({"previous": a.previous} if a.previous else {}) | {"ours": a.src}
    res: dict[tuple[str, str], list[dict[str, float]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        subprocess.run([sys.executable, "-c", "from mhtrack.cli.main import main; main()",
                        "simulate", "opensky-radars", "--seed", str(a.seed), "--no-attributes",
                        "--out", str(d)],
                       capture_output=True, check=True,
                       env={**os.environ, "PYTHONPATH": str(Path(a.src).resolve())})
        for _ in range(a.repeat):
            for birth in births:
                for lib, src in libs.items():
                    res.setdefault((lib, birth), []).append(run_track(src, d, birth))
    print(f"opensky-radars seed {a.seed}, {a.repeat} rounds (medians), ms per frame:")
    print("| library | birth | frames | birth propose | tracker step | step / every-plot |")
    print("|---|---|---|---|---|---|")
    for lib in libs:
        base = statistics.median(r["step"] / r["frames"] for r in res[(lib, "every-plot")])
        for birth in births:
            rs = res[(lib, birth)]
            prop = statistics.median(1e3 * r["propose"] / r["frames"] for r in rs)
            step = statistics.median(r["step"] / r["frames"] for r in rs)
            print(f"| {lib} | {birth} | {int(rs[0]['frames'])} | {prop:.3f} | "
                  f"{1e3 * step:.3f} | {step / base:.2f}x |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
