"""Outputs under hostile conditions (issue 33): names of 242–255 bytes, a full disk, other
OS errors, SIGTERM/SIGINT during a write (subprocesses, derandomised kill points), and
temporaries left by SIGKILL (recognisable, ignored by readers, removed by the next write
in the folder only when their writer is provably gone)."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from mhtrack.errors import InputError
from mhtrack.io import atomic
from mhtrack.io.atomic import OutputError, atomic_path, atomic_write, is_temporary
from mhtrack.io.paths import check_output_file

SRC = str(Path(atomic.__file__).parents[2])


def _temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if is_temporary(p))


@pytest.mark.parametrize("n", [242, 250, 255])
def test_any_name_the_file_system_accepts_is_written(tmp_path: Path, n: int) -> None:
    """Before: the temporary was ``.NAME.XXXXXXXX.csv``, 14+ bytes longer than the name,
    so names of 242–255 bytes failed (ENAMETOOLONG) after all the work."""
    path = tmp_path / ("a" * (n - 4) + ".csv")
    check_output_file(path)
    atomic_write(path, "x,y\n1,2\n")
    assert path.read_text() == "x,y\n1,2\n" and _temporaries(tmp_path) == []


def test_track_writes_an_output_name_of_255_bytes(tmp_path: Path) -> None:
    """Through the command: ``mhtrack track --out`` with a 255-byte name (before: refused
    after the tracking, the temporary's name being longer)."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    runner = CliRunner()
    sim = tmp_path / "s"
    assert runner.invoke(cli, ["simulate", "crossing", "--scans", "4", "--out",
                               str(sim)]).exit_code == 0
    out = tmp_path / ("t" * 251 + ".csv")
    res = runner.invoke(cli, ["track", str(sim / "plots.csv"), "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert out.read_text().startswith("scan,") and _temporaries(tmp_path) == []
    res = runner.invoke(cli, ["track", str(sim / "plots.csv"), "--out",
                              str(tmp_path / ("t" * 252 + ".csv"))])
    assert res.exit_code == 2 and "its name is 256 bytes long" in res.output, res.output


def test_a_name_too_long_is_refused_before_the_work(tmp_path: Path) -> None:
    path = tmp_path / ("a" * 252 + ".csv")
    with pytest.raises(InputError, match=r"its name is 256 bytes long, the file system "
                       r"allows 255"):
        check_output_file(path)


@pytest.mark.parametrize("where", ["write", "fsync"])
def test_disk_full_names_the_file_and_keeps_the_old_one(tmp_path: Path, where: str,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """ENOSPC while the writer writes or at the flush: one line naming the file, the old
    content kept, no temporary left (before: '[Errno 28] No space left on device')."""
    path = tmp_path / "out.csv"
    path.write_text("old\n")

    def full(*args: object) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    if where == "fsync":
        monkeypatch.setattr(os, "fsync", full)
        with pytest.raises(OutputError) as e:
            atomic_write(path, "new\n")
    else:
        with pytest.raises(OutputError) as e, atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:
                fh.write(b"half")
            full()
    assert str(e.value) == f"{path}: cannot write (No space left on device: the disk is full)"
    assert isinstance(e.value, OSError) and e.value.errno == errno.ENOSPC
    assert path.read_text() == "old\n" and _temporaries(tmp_path) == []


def test_disk_full_through_a_command_is_one_line(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """``mhtrack simulate`` on a full disk: exit 2 and one line naming the file."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    def full(fd: int) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)
    res = CliRunner().invoke(cli, ["simulate", "crossing", "--scans", "3", "--out",
                                   str(tmp_path / "d")])
    assert res.exit_code == 2, res.output
    assert "plots.csv: cannot write (No space left on device: the disk is full)" in res.output
    assert "Traceback" not in res.output


_WRITER = textwrap.dedent("""
    import os, sys, time
    sys.path.insert(0, {src!r})
    from mhtrack.io import atomic
    atomic.install_signal_cleanup()
    out, chunks = sys.argv[1], int(sys.argv[2])
    with atomic.temporary_dir() as d, atomic.atomic_path(out) as tmp, open(tmp, "wb") as fh:
        (d / "decoded.bin").write_bytes(b"x" * 1000)
        for i in range(10**6):
            fh.write(b"y" * 4096)
            fh.flush()
            if i == chunks:
                print(tmp, d, flush=True)
            time.sleep(0.001)
""")


def _writer(tmp_path: Path, chunks: int) -> tuple[subprocess.Popen[str], Path, Path]:
    script = tmp_path / "writer.py"
    script.write_text(_WRITER.format(src=SRC))
    out = tmp_path / "out" / "result.csv"
    out.parent.mkdir(exist_ok=True)
    out.write_text("old\n")
    p = subprocess.Popen([sys.executable, str(script), str(out), str(chunks)],
                         stdout=subprocess.PIPE, text=True)
    line = p.stdout.readline().split()  # type: ignore[union-attr]
    return p, Path(line[0]), Path(line[1])


@pytest.mark.parametrize("chunks", list(np.random.default_rng(33).integers(0, 50, 3)))
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_during_a_write_leaves_no_temporary(tmp_path: Path, sig: int,
                                                   chunks: int) -> None:
    """SIGTERM or SIGINT after ``chunks`` writes (seeded): the old output is kept, the
    temporary and the registered temporary folder are gone."""
    p, tmp, d = _writer(tmp_path, int(chunks))
    assert tmp.exists() and d.exists()
    p.send_signal(sig)
    rc = p.wait()
    # SIGTERM: status 143; SIGINT: KeyboardInterrupt, which Python ends by SIGINT itself
    assert rc == (143 if sig == signal.SIGTERM else -signal.SIGINT)
    assert (tmp_path / "out" / "result.csv").read_text() == "old\n"
    assert _temporaries(tmp_path / "out") == [] and not d.exists()


def test_sigkill_leaves_a_recognisable_temporary_removed_by_the_next_write(
        tmp_path: Path) -> None:
    """SIGKILL cannot be caught: the temporary stays, named with the writer's pid; a
    reader listing the folder skips it; the next write in the folder removes it (its pid
    is gone), but never the temporary of a live writer."""
    p, tmp, _ = _writer(tmp_path, 3)
    p.kill()
    p.wait()
    folder = tmp_path / "out"
    assert _temporaries(folder) == [tmp.name]
    m = atomic.TEMP_NAME.fullmatch(tmp.name)
    assert m is not None and int(m[1]) == p.pid
    live, live_tmp, _ = _writer(tmp_path / "out" / "..", 2)  # a live writer, same folder
    try:
        atomic._CLEANED.discard(os.fspath(folder.absolute()))
        atomic_write(folder / "other.csv", "z\n")
        assert not tmp.exists() and live_tmp.exists()
    finally:
        live.terminate()
        live.wait()
    assert (folder / "result.csv").read_text() == "old\n"


def test_a_temporary_of_a_reused_pid_without_its_lock_is_stale(tmp_path: Path) -> None:
    """A temporary whose pid runs again (here: this test's own pid, and pid 1) but whose
    lock nobody holds is stale: a pid alone is not proof, the lock is."""
    mine = tmp_path / f".mhtrack-{os.getpid()}-0123456789ab.tmp.csv"
    init = tmp_path / ".mhtrack-1-0123456789ab.tmp.json"
    other = tmp_path / "data.csv"
    for f in (mine, init, other):
        f.write_text("x")
    assert sorted(p.name for p in atomic.remove_stale(tmp_path)) == sorted(
        [mine.name, init.name])
    assert other.exists()


def test_readers_skip_temporaries(tmp_path: Path) -> None:
    """The study page takes the first ``*.json`` with paired comparisons: a half-written
    temporary sorted before the real file (``.`` sorts first) is not read."""
    import json

    from mhtrack.reports.html_study import PAIRED_FIELDS, paired_from_json

    row = dict.fromkeys(PAIRED_FIELDS, 1.0)
    (tmp_path / ".mhtrack-99999999-0123456789ab.tmp.json").write_text(
        json.dumps({"paired": [{**row, "note": "half"}]}))
    (tmp_path / "results.json").write_text(json.dumps({"paired": [row]}))
    assert is_temporary(tmp_path / ".mhtrack-99999999-0123456789ab.tmp.json")
    assert not is_temporary(tmp_path / "results.json")
    assert paired_from_json(tmp_path)[1] == "results.json"


_COMMAND = textwrap.dedent("""
    import sys, time
    sys.path.insert(0, {src!r})
    import pyarrow.csv as pacsv
    from mhtrack.io import atomic
    real, k = pacsv.write_csv, int(sys.argv[1])
    def slow(table, fh, *args, **kw):  # the command's own writer, slowed down at row k
        real(table.slice(0, k), fh, *args, **kw)
        fh.flush()
        print(list(atomic._IN_FLIGHT)[0], flush=True)
        while True:
            time.sleep(0.01)
    pacsv.write_csv = slow
    from mhtrack.cli.main import cli
    cli(sys.argv[2:], prog_name="mhtrack")
""")


@pytest.mark.parametrize("k", list(np.random.default_rng(7).integers(0, 200, 2)))
def test_sigterm_during_a_command_keeps_the_old_output_and_no_temporary(
        tmp_path: Path, k: int) -> None:
    """``mhtrack simulate`` stopped by SIGTERM while it writes plots.csv (after ``k`` rows,
    seeded): status 143, the previous plots.csv whole, no temporary left."""
    out = tmp_path / "sim"
    out.mkdir()
    (out / "plots.csv").write_text("old\n")
    script = tmp_path / "cmd.py"
    script.write_text(_COMMAND.format(src=SRC))
    p = subprocess.Popen([sys.executable, str(script), str(k), "simulate", "crossing",
                          "--scans", "20", "--out", str(out)], stdout=subprocess.PIPE,
                         text=True)
    tmp = Path(p.stdout.readline().strip())  # type: ignore[union-attr]
    assert tmp.exists() and is_temporary(tmp) and tmp.parent == out
    p.terminate()
    assert p.wait() == 143
    assert (out / "plots.csv").read_text() == "old\n" and _temporaries(out) == []


_TRACKING = textwrap.dedent("""
    import sys, time
    sys.path.insert(0, {src!r})
    from mhtrack.mht import MHTTracker
    real = MHTTracker.step
    calls = [0]
    def step(self, scan):  # tracking, with the decoded recording on disk
        calls[0] += 1
        if calls[0] == int(sys.argv[1]):
            print("tracking", flush=True)
            while True:
                time.sleep(0.01)
        return real(self, scan)
    MHTTracker.step = step
    from mhtrack.cli.main import cli
    cli(sys.argv[2:], prog_name="mhtrack")
""")


def test_sigterm_while_tracking_a_recording_leaves_nothing(tmp_path: Path) -> None:
    """``mhtrack track REC.pcap`` decodes the recording in memory (no temporary folder);
    SIGTERM while tracking (at a seeded frame) leaves no temporary and no output."""
    pytest.importorskip("asterix")
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    sim = tmp_path / "sim"
    runner = CliRunner()
    assert runner.invoke(cli, ["simulate", "opensky-radars", "--out", str(sim)]).exit_code == 0
    rec = sim / "radar.pcap"
    assert runner.invoke(cli, ["export", str(sim / "plots.csv"), "--sensors",
                               str(sim / "sensors.toml"), "--out", str(rec)]).exit_code == 0
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    script = tmp_path / "cmd.py"
    script.write_text(_TRACKING.format(src=SRC))
    frame = int(np.random.default_rng(11).integers(1, 200))
    p = subprocess.Popen([sys.executable, str(script), str(frame), "track", str(rec),
                          "--sensors", str(sim / "sensors.toml"), "--out",
                          str(tmp_path / "tracks.csv")], stdout=subprocess.PIPE, text=True,
                         env={**os.environ, "TMPDIR": str(tmpdir)})
    assert p.stdout.readline().strip() == "tracking"  # type: ignore[union-attr]
    assert list(tmpdir.iterdir()) == []  # the recording is decoded in memory, never to disk
    p.terminate()
    assert p.wait() == 143
    assert list(tmpdir.iterdir()) == [] and not (tmp_path / "tracks.csv").exists()
    assert _temporaries(tmp_path) == []
