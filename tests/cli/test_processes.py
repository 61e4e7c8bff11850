"""Worker processes end with the ``mhtrack`` process that started them (SIGKILL or Ctrl-C),
and the study it ran resumes. Each test polls a bounded number of times; none asserts a
duration."""

import os
import signal
import subprocess
import sys
import time

import pytest

psutil = pytest.importorskip("psutil")

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="process tree checks written for Linux")

POLLS = 600  # × 0.1 s
STUDY = ["montecarlo", "crossing", "--trackers", "mht-agmm", "--scans", "25", "--runs",
         "12", "--seed", "3", "--workers", "2", "--no-progress"]


def mhtrack(*args):
    return [sys.executable, "-c", "from mhtrack.cli.main import main; main()", *args]


def start(out):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    return subprocess.Popen(mhtrack(*STUDY, "--out", str(out)), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)


def wait_for_first_run(proc, out):
    runs = out / "runs" / "mht-agmm"
    for _ in range(POLLS):
        if runs.is_dir() and list(runs.glob("run-*.parquet")):  # not a temporary file
            return
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.1)
    pytest.fail("no run was stored")


def gone(p):
    try:
        return p.status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


def assert_children_end(children):
    for _ in range(POLLS):
        if all(gone(c) for c in children):
            return
        time.sleep(0.1)
    pytest.fail(f"worker processes still running: {[c.pid for c in children if not gone(c)]}")


def resume(out):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    r = subprocess.run(mhtrack(*STUDY, "--out", str(out)), capture_output=True, text=True,
                       env=env)
    assert r.returncode == 0, r.stderr
    return r.stdout


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT])
def test_workers_end_with_their_parent_and_the_study_resumes(tmp_path, sig):
    out = tmp_path / "mc"
    proc = start(out)
    try:
        wait_for_first_run(proc, out)
        children = psutil.Process(proc.pid).children(recursive=True)
        assert children, "the study runs in worker processes"
        proc.send_signal(sig)
        _, stderr = proc.communicate(timeout=POLLS / 10)
        assert_children_end(children)
    finally:
        if proc.poll() is None:
            proc.kill()
    if sig == signal.SIGINT:
        assert proc.returncode == 130
        assert "interrupted; every finished run is stored" in stderr
        assert "Resume with" in stderr and f"--out {out}" in stderr
        assert "Traceback" not in stderr
    done = sorted((out / "runs" / "mht-agmm").glob("run-*.parquet"))
    assert not list((out / "runs" / "mht-agmm").glob("*.error.txt"))
    stdout = resume(out)
    assert f"{12 - len(done)} runs computed, {len(done)} already done" in stdout
    assert len(done) >= 1
