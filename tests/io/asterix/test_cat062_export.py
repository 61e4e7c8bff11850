"""``mhtrack export --category 062`` encodes through the CAT062 sinks' NumPy encoder
(:func:`~mhtrack.io.asterix.cat062_fast.row_blocks`): the file it writes is, byte for
byte, the one the former libasterix path wrote (``encode_blocks(track_messages(...))``
of the same rows), for a tracker run on ``simulate`` output with and without SSR
attributes; the values the NumPy encoder does not cover never reach it from a tracks
file (the reader refuses them)."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

pytest.importorskip("asterix.generated", reason="libasterix not installed")

import mhtrack.io.asterix.cat062 as cat062
import mhtrack.io.asterix.cat062_export as cat062_export
from mhtrack.cli.main import cli
from mhtrack.io.asterix.cat062_fast import row_blocks
from mhtrack.io.asterix.encode import encode_blocks


def _run(*args: object) -> None:
    r = CliRunner().invoke(cli, [str(a) for a in args])
    assert r.exit_code == 0, r.output


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Tracks files of a tracker run on four scans of opensky-radars, with and without
    SSR attributes (``simulate --attributes`` / ``--no-attributes``)."""
    out = {}
    for flag in ("--attributes", "--no-attributes"):
        d = tmp_path_factory.mktemp("export062")
        _run("simulate", "opensky-radars", "--seed", 3, "--scans", 4, flag, "--out", d)
        _run("track", d / "plots.csv", "--sensors", d / "sensors.toml", "--out",
             d / "tracks.csv", "-q")
        out[flag] = d / "tracks.csv"
    return out


def _libasterix(values, attrs, *, sac=None, sic=None, bar=None):
    """The former encoding of ``export --category 062``: a libasterix message per row."""
    return encode_blocks(cat062.track_messages(*values, sac=sac, sic=sic, attrs=attrs),
                         bar)


def _export_both(monkeypatch: pytest.MonkeyPatch, path: Path, out: Path,
                 *args: object) -> tuple[bytes, bytes]:
    """The bytes ``export --category 062`` writes now, and with the former encoder."""
    _run("export", path, "--category", "062", "--out", out.with_suffix(".fast" +
         out.suffix), *args)
    with monkeypatch.context() as m:
        m.setattr(cat062_export, "row_blocks", _libasterix)
        _run("export", path, "--category", "062", "--out", out, *args)
    return out.with_suffix(".fast" + out.suffix).read_bytes(), out.read_bytes()


@pytest.mark.parametrize("flag", ["--attributes", "--no-attributes"])
@pytest.mark.parametrize("suffix, args", [(".ast", ()), (".pcap", ("--sac", 7, "--sic", 9))])
def test_export_same_bytes_as_libasterix(runs: dict[str, Path], tmp_path: Path,
                                         monkeypatch: pytest.MonkeyPatch, flag: str,
                                         suffix: str, args: tuple) -> None:
    tracks = runs[flag]
    lines = tracks.read_text().splitlines()
    assert ("mode_3a" in lines[0].split(",")) == (flag == "--attributes")
    rows = len(lines) - 1
    assert rows > 100
    fast, ref = _export_both(monkeypatch, tracks, tmp_path / f"t{suffix}", *args)
    assert fast == ref
    # the core record is 25 octets; with attributes most rows carry more items
    assert len(ref) > (30 if flag == "--attributes" else 25) * rows


@pytest.mark.parametrize("column, value", [
    ("mode_3a", "10000"), ("address", "1000000"), ("meas_mode_3a", "10000"),
    ("meas_mode_3a_vg", "4"), ("meas_flight_level_vg", "4"), ("meas_range", "-5000.0")])
def test_values_not_covered_are_refused_by_the_reader(runs: dict[str, Path],
                                                      tmp_path: Path, column: str,
                                                      value: str) -> None:
    """Each value :mod:`.cat062_attr_octets` does not cover (``covered``: codes beyond
    12 bits, addresses beyond 24, V/G beyond 0–3, a negative measured range) is refused
    by the tracks file's reader with its line and column: a tracks file the export
    accepts is encoded by NumPy throughout (the libasterix fall-back serves the sinks'
    in-memory rows)."""
    lines = runs["--attributes"].read_text().splitlines()
    header = lines[0].split(",")
    cells = lines[1].split(",")
    cells[header.index(column)] = value
    if column == "meas_range":  # a measured position: with a sensor and a bearing
        cells[header.index("meas_sensor")] = cells[header.index("meas_sensor")] or "1"
        cells[header.index("meas_bearing")] = cells[header.index("meas_bearing")] or "10"
    path = tmp_path / "bad.csv"
    path.write_text("\n".join([lines[0], ",".join(cells), *lines[2:]]) + "\n")
    r = CliRunner().invoke(cli, ["export", str(path), "--category", "062", "--out",
                                 str(tmp_path / "bad.ast")])
    assert r.exit_code == 2 and "line 2" in r.output and f"'{column}'" in r.output, \
        r.output
    assert not (tmp_path / "bad.ast").exists()


def test_row_blocks_counts_every_row() -> None:
    """``bar`` counts the rows encoded, on the NumPy path as on libasterix's."""
    import numpy as np

    class Bar:
        n = 0

        def update(self, k: int) -> None:
            self.n += k

    def check(bad, column, text):
        assert not bad.any()

    n = 95
    z = np.zeros(n)
    values = (np.arange(n, dtype=float), np.arange(n), z + 50.0, z + 8.0, z, z,
              np.zeros(n, int), np.zeros(n, int), check)
    fast, ref = Bar(), Bar()
    blocks = list(row_blocks(values, None, bar=fast))  # type: ignore[arg-type]
    assert blocks == list(_libasterix(values, None, bar=ref))
    assert fast.n == ref.n == n and len(blocks) == 3
