"""SIGTERM and SIGKILL in the middle of ``export``, ``track`` (a recording in) and
``run --report`` (issue 33; the full 20 + 20 per command at seeded moments is
``benchmarks/signals.py``).

Each command runs in a child that stalls at its ``k``-th output write (seeded), at the
worst moment: the temporary complete on disk, not yet renamed. The child prints the
temporary's path; the test then signals it. Checked against the outputs of the same
command run to the end (the "new" one) and before with other options (the "old" one):

* every file of the folder is the old file or the new one, byte for byte;
* SIGTERM: status 143, no temporary in the folder, nothing in the child's ``TMPDIR``;
* SIGKILL: the temporary stays; the next run in the folder removes it and writes the
  new output.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from mhtrack.io.atomic import is_temporary

SRC = str(Path(__file__).resolve().parents[2] / "src")

_STALLED = textwrap.dedent("""
    import sys, time
    sys.path.insert(0, {src!r})
    from mhtrack.io import atomic
    real, k, calls = atomic._fsync, int(sys.argv[1]), [0]
    def stalled(path):  # the k-th output written whole, before its rename
        real(path)
        calls[0] += 1
        if calls[0] == k:
            print(path, flush=True)
            while True:
                time.sleep(0.01)
    atomic._fsync = stalled
    from mhtrack.cli.main import cli
    cli(sys.argv[2:], prog_name="mhtrack")
""")


def _env(tmpdir: Path | None = None) -> dict[str, str]:
    env = {**os.environ, "PYTHONPATH": SRC}
    if tmpdir is not None:
        env["TMPDIR"] = str(tmpdir)
    return env


def _mhtrack(args: list[str], cwd: Path | None = None) -> None:
    r = subprocess.run([sys.executable, "-c", "from mhtrack.cli.main import main; main()",
                        *args], env=_env(), capture_output=True, text=True, cwd=cwd)
    assert r.returncode == 0, r.stderr


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    pytest.importorskip("asterix")
    d = tmp_path_factory.mktemp("signals")
    _mhtrack(["simulate", "opensky-radars", "--seed", "1", "--scans", "3", "--out",
              str(d / "sim")])
    lines = (d / "sim" / "plots.csv").read_text().splitlines(keepends=True)
    (d / "sim" / "half.csv").write_text("".join(lines[:len(lines) // 2]))
    _mhtrack(["export", str(d / "sim" / "plots.csv"), "--sensors",
              str(d / "sim" / "sensors.toml"), "--out", str(d / "sim" / "rec.pcap")])
    return d / "sim"


def _commands(sim: Path) -> dict[str, tuple[list[str], list[str]]]:
    """Per command: (args of the new output, args of the old one), ``{out}`` the folder."""
    s = str(sim / "sensors.toml")
    return {
        "export": (["export", str(sim / "plots.csv"), "--sensors", s, "--out",
                    "{out}/rec.pcap"],
                   ["export", str(sim / "half.csv"), "--sensors", s, "--out",
                    "{out}/rec.pcap"]),
        "track": (["track", str(sim / "rec.pcap"), "--sensors", s, "--out",
                   "{out}/tracks.csv"],
                  ["track", str(sim / "rec.pcap"), "--sensors", s, "--tracker", "mht",
                   "--out", "{out}/tracks.csv"]),
        "run": (["run", "crossing", "--seed", "1", "--scans", "8", "--report", "--out",
                 "{out}"],
                ["run", "crossing", "--seed", "2", "--scans", "8", "--report", "--out",
                 "{out}"]),
    }


#: (command, signal, k: which output write the child stalls at), seeded for run.
CASES = [("export", signal.SIGTERM, 1), ("export", signal.SIGKILL, 1),
         ("track", signal.SIGTERM, 1), ("track", signal.SIGKILL, 1),
         *[("run", sig, int(k)) for sig, k in zip(
             (signal.SIGTERM, signal.SIGKILL), np.random.default_rng(33).integers(1, 8, 2),
             strict=True)]]


@pytest.mark.parametrize(("name", "sig", "k"), CASES,
                         ids=[f"{c[0]}-{signal.Signals(c[1]).name}-{c[2]}" for c in CASES])
def test_signal_mid_command_keeps_old_or_new_and_leaves_no_temporary(
        tmp_path: Path, inputs: Path, name: str, sig: int, k: int) -> None:
    if name == "run":
        pytest.importorskip("plotly")
    new_args, old_args = _commands(inputs)[name]
    def fill(args: list[str], out: Path) -> list[str]:
        return [a.replace("{out}", str(out)) for a in args]

    new_dir, old_dir, out = tmp_path / "new", tmp_path / "old", tmp_path / "out"
    for d in (new_dir, old_dir, tmp_path / "again"):
        d.mkdir()
    _mhtrack(fill(new_args, new_dir))
    _mhtrack(fill(old_args, old_dir))
    new, old = _files(new_dir), _files(old_dir)
    assert new != old
    _mhtrack(fill(new_args, tmp_path / "again"))  # files holding run times differ
    volatile = {n for n, data in _files(tmp_path / "again").items() if data != new[n]}
    assert volatile <= {"metrics.json", "report.html"}, volatile
    shutil.copytree(old_dir, out)
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    script = tmp_path / "stalled.py"
    script.write_text(_STALLED.format(src=SRC))
    p = subprocess.Popen([sys.executable, str(script), str(k), *fill(new_args, out)],
                         env=_env(tmpdir), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True)
    line = p.stdout.readline().strip()  # type: ignore[union-attr]
    assert line, p.communicate()[1]
    tmp = Path(line)
    assert tmp.parent == out and is_temporary(tmp.name) and tmp.exists()
    p.send_signal(sig)
    p.communicate()
    assert p.returncode == (143 if sig == signal.SIGTERM else -signal.SIGKILL)
    for n, data in _files(out).items():  # never half, never another file
        assert is_temporary(n) or data in (new.get(n), old.get(n)) or (
            n in volatile and _whole(n, data)), n
    left = [n for n in _files(out) if is_temporary(n)]
    if sig == signal.SIGTERM:
        assert left == [] and list(tmpdir.iterdir()) == []
        return
    assert left == [tmp.name]  # SIGKILL cannot be caught: the temporary stays
    _mhtrack(fill(new_args, out))  # the next run in that folder
    after = _files(out)  # the stale temporary removed, the new output whole
    assert sorted(after) == sorted(new)
    assert all(after[n] == new[n] or (n in volatile and _whole(n, after[n])) for n in new)


def _whole(name: str, data: bytes) -> bool:
    """A file whose bytes hold a run time (``t_avg``): whole JSON, or an HTML page that
    ends."""
    if name.endswith(".json"):
        import json

        return isinstance(json.loads(data), dict)
    return data.rstrip().endswith(b"</html>")
