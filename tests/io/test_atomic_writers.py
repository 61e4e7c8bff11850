"""Every writer goes through :mod:`mhtrack.io.atomic`: a write interrupted after writing
part of its output leaves the old file byte for byte and no temporary file beside it."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from mhtrack.clutter.known import KnownClutter
from mhtrack.io import write_plots, write_scenario_toml
from mhtrack.io.atomic import atomic_write
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.state import save_state
from mhtrack.records import PlotTable


class Interrupted(Exception):
    """Stands for a crash (or Ctrl-C) in the middle of a write."""


def _plots() -> PlotTable:
    n = 4
    return PlotTable(scan=np.arange(n), time=np.arange(n, dtype=float),
                     sensor=np.zeros(n, np.int64), x=np.linspace(0.0, 3.0, n),
                     y=np.linspace(1.0, 4.0, n))


def _half_then_fail(target: Any, name: str, monkeypatch: pytest.MonkeyPatch,
                    dest_arg: Callable[[tuple[Any, ...], dict[str, Any]], Any]) -> None:
    """Replace ``target.name`` by a writer that writes some bytes to its destination
    (path or open file) and then raises :class:`Interrupted`."""

    def fake(*args: Any, **kwargs: Any) -> None:
        dest = dest_arg(args, kwargs)
        if hasattr(dest, "write"):
            dest.write(b"partial")
        else:
            Path(dest).write_bytes(b"partial")
        raise Interrupted

    monkeypatch.setattr(target, name, fake)


def _assert_untouched(path: Path, old: bytes) -> None:
    assert path.read_bytes() == old
    assert [f.name for f in path.parent.iterdir()] == [path.name]  # no temporary left


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_interrupted_table_write_keeps_old_file(tmp_path: Path, fmt: str,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    path = tmp_path / f"plots.{fmt}"
    write_plots(_plots(), path)
    old = path.read_bytes()
    if fmt == "csv":
        _half_then_fail(pacsv, "write_csv", monkeypatch, lambda a, k: a[1])
    else:
        _half_then_fail(pq, "write_table", monkeypatch, lambda a, k: a[1])
    with pytest.raises(Interrupted):
        write_plots(_plots(), path)
    _assert_untouched(path, old)


def test_interrupted_state_write_keeps_old_file(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "state.npz"
    path.write_bytes(b"old state")
    _half_then_fail(np, "savez", monkeypatch, lambda a, k: a[0])
    with pytest.raises(Interrupted):
        save_state(path, {}, KnownClutter(1e-9), MHTConfig(), {})
    _assert_untouched(path, b"old state")


def test_interrupted_figure_write_keeps_old_file(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    from matplotlib.figure import Figure

    from mhtrack.plotting.scene import save_figure

    path = tmp_path / "scene.png"
    path.write_bytes(b"old png")
    _half_then_fail(Figure, "savefig", monkeypatch, lambda a, k: a[1])
    with pytest.raises(Interrupted):
        save_figure(Figure(), path)
    _assert_untouched(path, b"old png")


def test_toml_write_interrupted_before_rename_keeps_old_file(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The whole new text is written, but the crash comes before it is on disk."""
    path = tmp_path / "scenario.toml"
    path.write_bytes(b"T = 1\n")

    def fail(fd: int) -> None:
        raise Interrupted

    monkeypatch.setattr(os, "fsync", fail)
    with pytest.raises(Interrupted):
        write_scenario_toml({"T": 2}, path)
    _assert_untouched(path, b"T = 1\n")


def test_written_file_has_ordinary_permissions(tmp_path: Path) -> None:
    """Not mkstemp's owner-only 0o600: the mode ``open(path, "w")`` gives."""
    plain = tmp_path / "plain.txt"
    with open(plain, "w") as fh:
        fh.write("x")
    atomic = atomic_write(tmp_path / "atomic.txt", "x")
    assert os.stat(atomic).st_mode == os.stat(plain).st_mode
