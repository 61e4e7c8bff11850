"""The first hour on a simulated radar recording (issue 31, acceptance): ``mhtrack simulate
opensky-radars --seed S`` → ``export`` (pcap) → ``track`` with defaults only →
``evaluate`` against the truth, as a new user runs them.

Per seed: fragmentations, identity switches, coverage and OSPA mean (c = 500 m, p = 2) of
``evaluate --json``. The library is the one at ``--src`` (``PYTHONPATH``), so the same
script measures two versions (e.g. main before a change and a branch after it); every
further argument after ``--`` goes to ``simulate`` (e.g. ``--no-attributes``).
Single process (the machine is shared)::

    python benchmarks/bench_ssr_default.py --src /tmp/base/src 1 2 3
    python benchmarks/bench_ssr_default.py --src src 1 2 3
    python benchmarks/bench_ssr_default.py --src src 1 2 3 -- --no-attributes
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

#: (key in evaluate's JSON, label).
FIGURES = (("fragmentations", "fragmentations"), ("id_switches", "ID switches"),
           ("coverage", "coverage"), ("ospa_mean", "OSPA (m)"))


def _mhtrack(src: Path, args: list[str], cwd: Path) -> str:
    env = {**os.environ, "PYTHONPATH": str(src.resolve())}
    r = subprocess.run([sys.executable, "-c", "from mhtrack.cli.main import main; main()",
                        *args], cwd=cwd, env=env, capture_output=True, text=True,
                       check=False)
    if r.returncode != 0:
        raise SystemExit(f"mhtrack {' '.join(args)} failed:\n{r.stderr}")
    return r.stdout


def run_seed(src: Path, seed: int, extra: list[str], tmp: Path) -> dict[str, float]:
    """The figures of one seed (the module docstring's commands)."""
    _mhtrack(src, ["simulate", "opensky-radars", "--seed", str(seed), "--out", "sim", "-q",
                   *extra], tmp)
    _mhtrack(src, ["export", "sim/plots.csv", "--sensors", "sim/sensors.toml", "--out",
                   "sim/radar.pcap", "-q"], tmp)
    _mhtrack(src, ["track", "sim/radar.pcap", "--sensors", "sim/sensors.toml", "--out",
                   "sim/tracks.csv", "-q"], tmp)
    ev = json.loads(_mhtrack(src, ["evaluate", "sim/tracks.csv", "sim/truth.csv", "--json",
                                   "-q"], tmp))
    return {k: float(ev[k]) for k, _ in FIGURES}


def main() -> None:
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    argv = argv[:argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", type=Path, required=True, help="the library's src directory")
    ap.add_argument("seeds", type=int, nargs="*", default=[1, 2, 3])
    a = ap.parse_args(argv)
    print("| seed | " + " | ".join(label for _, label in FIGURES) + " |")
    print("|---|" + "---|" * len(FIGURES), flush=True)
    for seed in a.seeds:
        with tempfile.TemporaryDirectory() as tmp:
            f = run_seed(a.src, seed, extra, Path(tmp))
        print(f"| {seed} | {f['fragmentations']:.0f} | {f['id_switches']:.0f} | "
              f"{f['coverage']:.4f} | {f['ospa_mean']:.1f} |", flush=True)


if __name__ == "__main__":
    main()
