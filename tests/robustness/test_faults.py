"""Fault tests: a process killed (SIGKILL) in the middle of writing a file leaves the old
file whole and no partial file under the output's name; a Monte-Carlo study killed
mid-run keeps its finished runs and resumes to the result of an uninterrupted study."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from mhtrack.io import read_tracks, write_tracks
from mhtrack.records import TrackTable

SRC = str(Path(__file__).resolve().parents[2] / "src")

#: The child writes half of the table, flushes it to disk, then stalls (a slow disk)
#: until it is killed.
CHILD = r"""
import sys, time
import numpy as np
import pyarrow.csv as pacsv
from mhtrack.io import write_tracks
from mhtrack.records import TrackTable

real = pacsv.write_csv
def stalled(table, fh, *a, **k):
    real(table.slice(0, table.num_rows // 2), fh, *a, **k)
    fh.flush()
    print("half", flush=True)
    time.sleep(60)
    real(table.slice(table.num_rows // 2), fh, *a, **k)
pacsv.write_csv = stalled
n = 20000
t = TrackTable(scan=np.repeat(np.arange(n // 4), 4), time=np.repeat(np.arange(n // 4), 4) * 1.0,
               track_id=np.tile(np.arange(4), n // 4), x=np.ones(n), y=np.ones(n),
               vx=np.zeros(n), vy=np.zeros(n), plot=np.full(n, -1))
write_tracks(t, sys.argv[1])
"""


def _tracks(n: int) -> TrackTable:
    k = np.arange(n)
    return TrackTable(scan=k, time=k * 1.0, track_id=np.zeros(n, np.int64), x=k * 2.0,
                      y=k * 3.0, vx=np.ones(n), vy=np.ones(n), plot=np.full(n, -1))


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}


def test_write_killed_midway_leaves_the_old_file_whole(tmp_path: Path) -> None:
    path = tmp_path / "tracks.csv"
    write_tracks(_tracks(5), path)
    old = path.read_bytes()
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(path)], env=_env(),
                             stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None
        assert child.stdout.readline().strip() == "half"  # half written, on disk
        partial = [p for p in tmp_path.iterdir() if p.name != "tracks.csv"]
        assert len(partial) == 1 and partial[0].stat().st_size > 0
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait()
    assert child.returncode == -signal.SIGKILL
    assert path.read_bytes() == old  # the old file, whole
    back = read_tracks(path)
    assert np.array_equal(back.x, _tracks(5).x)
    # the half-written temporary is a hidden file that no reader looks for
    from mhtrack.cli.common import table_path

    leftovers = [p.name for p in tmp_path.iterdir() if p.name != "tracks.csv"]
    from mhtrack.io.atomic import is_temporary

    assert all(is_temporary(name) for name in leftovers), leftovers
    assert table_path(tmp_path, "tracks") == path


def test_writer_raising_midway_leaves_no_partial_file(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    import pyarrow.csv as pacsv

    path = tmp_path / "tracks.csv"
    real = pacsv.write_csv

    def fail(table, fh, *a, **k):  # type: ignore[no-untyped-def]
        real(table.slice(0, 2), fh, *a, **k)
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(pacsv, "write_csv", fail)
    with pytest.raises(Exception, match="No space left on device"):
        write_tracks(_tracks(10), path)
    assert list(tmp_path.iterdir()) == []  # nothing that could read as tracks


#: Runs of the killed study: enough that the kill (polled every 10 ms) falls mid-study
#: even on an idle machine.
RUNS = 12


def _montecarlo(out: Path) -> list[str]:
    return [sys.executable, "-c", "from mhtrack.cli.main import main; main()", "montecarlo",
            "crossing", "--runs", str(RUNS),
            "--scans", "8", "--trackers", "mht-agmm", "--workers", "1", "--no-progress",
            "--out", str(out)]


def test_study_killed_midrun_keeps_finished_runs_and_resumes(tmp_path: Path) -> None:
    from mhtrack.experiments.montecarlo import load_results

    out = tmp_path / "killed"
    runs = out / "runs" / "mht-agmm"
    child = subprocess.Popen(_montecarlo(out), env=_env(), stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        for _ in range(12000):  # until a run is finished (at most 120 s)
            done = sorted(runs.glob("run-*.parquet")) if runs.is_dir() else []
            if done or child.poll() is not None:
                break
            time.sleep(0.01)
    finally:
        os.killpg(child.pid, signal.SIGKILL)
        child.wait()
    finished = {p.name: p.read_bytes() for p in runs.glob("run-*.parquet")}
    assert 0 < len(finished) < RUNS, f"the kill did not fall mid-study ({len(finished)})"
    partial = load_results(out)
    assert len(partial.records["mht-agmm"]) == len(finished)

    r = subprocess.run(_montecarlo(out), env=_env(), capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert f"{RUNS - len(finished)} runs computed, {len(finished)} already done" in r.stdout
    for name, data in finished.items():  # finished runs kept as they were
        assert (runs / name).read_bytes() == data
    resumed = load_results(out)

    fresh_out = tmp_path / "fresh"
    r = subprocess.run(_montecarlo(fresh_out), env=_env(), capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    fresh = load_results(fresh_out)
    keys = ("ospa_mean", "gospa_mean", "n_tracks")
    got = [[rec.get(k) for k in keys] for rec in resumed.records["mht-agmm"]]
    want = [[rec.get(k) for k in keys] for rec in fresh.records["mht-agmm"]]
    assert got == want and len(got) == RUNS
