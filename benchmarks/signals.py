"""SIGTERM and SIGKILL at seeded random moments of ``mhtrack`` commands (issue 33,
acceptance run 2).

Usage: ``python benchmarks/signals.py [--per 20] [--seed 0] [--commands track,run,export]``.

Commands, each writing into a folder that already holds an older output (made by the
same command with other options, so that old and new differ):

* ``track REC.pcap --sensors S --out OUT/tracks.csv`` (the ``opensky-radars`` recording,
  seed 1: 110 s, 3 138 plots; the old output from ``--tracker mht``);
* ``run crossing --seed 1 --scans 40 --report --out OUT`` (plots, truth, tracks,
  metrics, two figures and the HTML report; the old output from seed 2);
* ``export plots.csv --sensors S --out OUT/rec.pcap`` (the old output: the first half
  of the plots).

One uninterrupted run of each gives the new output and its wall time ``T``. Each trial
starts the command in a fresh copy of the old folder, with its own ``TMPDIR``, and
sends the signal after a delay drawn uniformly from ``[0, 0.9 T]`` (seeded; a loaded
machine may still finish a command first: counted apart). Then:

* every file in the folder is the old file or the new one, byte for byte (never half,
  never another);
* after SIGTERM: status 143 (−15 when the signal came before the command had installed
  its handler, during start-up; 0 when it had already finished), no temporary in the
  folder (:func:`mhtrack.io.atomic.is_temporary`) and nothing in ``TMPDIR``;
* after SIGKILL: the command is run again in that folder to the end: no temporary is
  left there (the stale one of the killed writer removed) and the folder holds the new
  output.

Prints per command and signal the trials, how many signals fell while a temporary
existed in the folder (a write in flight), the temporaries SIGKILL left and the next run
removed, and the failures. Exit status 1 when any check failed.
"""

from __future__ import annotations

import argparse
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mhtrack.io.atomic import is_temporary

SRC = str(Path(__file__).resolve().parents[1] / "src")
MHTRACK = [sys.executable, "-c", "from mhtrack.cli.main import main; main()"]


def _env(tmpdir: Path | None = None) -> dict[str, str]:
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}
    if tmpdir is not None:
        env["TMPDIR"] = str(tmpdir)
    return env


def _run(args: list[str], tmpdir: Path | None = None) -> float:
    """Run ``mhtrack ARGS`` to the end; its wall time (s)."""
    t0 = time.perf_counter()
    r = subprocess.run(MHTRACK + args, env=_env(tmpdir), capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"mhtrack {' '.join(args)}: status {r.returncode}\n{r.stderr}")
    return time.perf_counter() - t0


#: Files that hold a run time (``t_avg``): whole, not byte-equal, is what is checked.
VOLATILE = {"metrics.json", "report.html"}


def _whole(name: str, data: bytes) -> bool:
    """A whole JSON object, or an HTML page that ends."""
    if name.endswith(".json"):
        import json

        try:
            return isinstance(json.loads(data), dict)
        except ValueError:
            return False
    return data.rstrip().endswith(b"</html>")


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def _temporaries(folder: Path) -> list[str]:
    return [p.name for p in folder.iterdir() if is_temporary(p.name)]


def prepare(work: Path) -> dict[str, tuple[list[str], list[str]]]:
    """The inputs; per command ``(args of the new output, args of the old one)`` with
    ``{out}`` for the output folder."""
    sim = work / "sim"
    _run(["simulate", "opensky-radars", "--seed", "1", "--no-attributes", "--out", str(sim)])
    sensors = str(sim / "sensors.toml")
    rec = str(sim / "rec.pcap")
    _run(["export", str(sim / "plots.csv"), "--sensors", sensors, "--out", rec])
    lines = (sim / "plots.csv").read_text().splitlines(keepends=True)
    (sim / "half.csv").write_text("".join(lines[:len(lines) // 2]))
    return {
        "track": (["track", rec, "--sensors", sensors, "--out", "{out}/tracks.csv"],
                  ["track", rec, "--sensors", sensors, "--tracker", "mht", "--out",
                   "{out}/tracks.csv"]),
        "run": (["run", "crossing", "--seed", "1", "--scans", "40", "--report", "--out",
                 "{out}"],
                ["run", "crossing", "--seed", "2", "--scans", "40", "--report", "--out",
                 "{out}"]),
        "export": (["export", str(sim / "plots.csv"), "--sensors", sensors, "--out",
                    "{out}/rec.pcap"],
                   ["export", str(sim / "half.csv"), "--sensors", sensors, "--out",
                    "{out}/rec.pcap"]),
    }


def _fill(args: list[str], out: Path) -> list[str]:
    return [a.replace("{out}", str(out)) for a in args]


def trial(args: list[str], old: Path, new: dict[str, bytes], old_files: dict[str, bytes],
          sig: int, delay: float, work: Path) -> tuple[list[str], bool, bool, int, int]:
    """One signal: ``(failures, write in flight at the signal, command finished before
    it, temporaries left, temporaries the next run removed)``."""
    out, tmpdir = work / "out", work / "tmp"
    for d in (out, tmpdir):
        shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(old, out)
    tmpdir.mkdir()
    p = subprocess.Popen(MHTRACK + _fill(args, out), env=_env(tmpdir),
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    in_flight = bool(_temporaries(out))
    finished = p.poll() is not None
    if not finished:
        p.send_signal(sig)
    try:
        _, err = p.communicate(timeout=600)
    except subprocess.TimeoutExpired:
        p.kill()
        p.communicate()
        return ["no end 600 s after the signal"], in_flight, finished, 0, 0
    fails = []
    # SIGTERM: 143 from mhtrack's handler; -15 when it came before the handler was
    # installed (interpreter start, imports: nothing written yet)
    expected = {0} if finished else ({143, -15, 0} if sig == signal.SIGTERM else {-9, 0})
    if p.returncode not in expected:
        fails.append(f"status {p.returncode}: {err.strip()[-300:]}")
    left = _temporaries(out)
    for name, data in _files(out).items():
        if is_temporary(name):
            continue
        if data != new.get(name) and data != old_files.get(name) and not (
                name in VOLATILE and _whole(name, data)):
            fails.append(f"{name}: neither the old file nor the new one "
                         f"({len(data)} bytes)")
    if sig == signal.SIGTERM:
        if left:
            fails.append(f"temporaries left in the folder: {left}")
        if any(tmpdir.iterdir()):
            fails.append(f"left in TMPDIR: {[q.name for q in tmpdir.iterdir()]}")
        return fails, in_flight, finished, len(left), 0
    try:
        _run(_fill(args, out), tmpdir)
    except RuntimeError as e:
        return [*fails, f"the next run failed: {e}"], in_flight, finished, len(left), 0
    still = _temporaries(out)
    if still:
        fails.append(f"the next run left temporaries: {still}")
    after = _files(out)
    if sorted(after) != sorted(new) or not all(
            after[n] == new[n] or (n in VOLATILE and _whole(n, after[n])) for n in new):
        fails.append("after the next run the folder is not the new output")
    return fails, in_flight, finished, len(left), len(set(left) - set(still))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per", type=int, default=20, help="signals of each kind per command")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--commands", default="track,run,export")
    ap.add_argument("--work", type=Path, default=None)
    args = ap.parse_args(argv)
    work = args.work or Path(tempfile.mkdtemp(prefix="signals-"))
    work.mkdir(parents=True, exist_ok=True)
    commands = prepare(work)
    rng = random.Random(args.seed)
    total_fail = 0
    print(f"{'command':8} {'signal':8} {'trials':>6} {'in a write':>10} "
          f"{'finished first':>14} {'temps left':>10} {'removed next':>12} {'failed':>6}",
          flush=True)
    for name in args.commands.split(","):
        new_args, old_args = commands[name]
        ref, old = work / f"{name}-new", work / f"{name}-old"
        for d in (ref, old):
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
        _run(_fill(old_args, old))
        wall = _run(_fill(new_args, ref))
        new, old_files = _files(ref), _files(old)
        assert new != old_files, "old and new must differ"
        for sig in (signal.SIGTERM, signal.SIGKILL):
            n = flight = first = left = removed = bad = 0
            for _ in range(args.per):
                delay = rng.uniform(0.0, 0.9 * wall)
                fails, in_flight, done, n_left, n_removed = trial(
                    new_args, old, new, old_files, sig, delay, work)
                n += 1
                flight += in_flight
                left += n_left
                removed += n_removed
                first += done
                if fails:
                    bad += 1
                    print(f"FAIL {name} {signal.Signals(sig).name} after {delay:.2f} s: "
                          + " | ".join(fails), flush=True)
            total_fail += bad
            print(f"{name:8} {signal.Signals(sig).name:8} {n:6d} {flight:10d} {first:14d} "
                  f"{left:10d} {removed:12d} {bad:6d}", flush=True)
    print(f"failed: {total_fail}")
    return 1 if total_fail else 0


if __name__ == "__main__":
    sys.exit(main())
