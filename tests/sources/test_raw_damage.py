"""A damaged raw recording (data blocks back to back) read by ``track`` (the streaming
:class:`~mhtrack.sources.recording.AsterixSource`) and by ``convert`` followed by
``track`` of the plots table (``tests/reference/recording_table.py``: ``read_recording``,
Parquet, ``read_plots``): the same frames bit for bit, the same file rows and the same
skip lines, on a hand-made stream whose surviving blocks are known (a damaged length
covering two good blocks, a category byte flipped, garbage between blocks, a cut
mid-block, all at once), on seeded damage of every kind (hypothesis), and a file that is
no recording refused by both with the same line. Both read through
:meth:`~mhtrack.io.asterix.decode.Decoder.units` (blocks judged by their content); before
it, the source read by framing alone and lost the blocks a damaged length covered."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from click.testing import CliRunner
from recording_table import recording_table
from tests.helpers.plot_blocks import plot_blocks

from mhtrack.cli.main import cli
from mhtrack.errors import InputError
from mhtrack.io.asterix import read_recording
from mhtrack.io.sensors import read_sensors, write_sensors
from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.records import Scan
from mhtrack.sources import open_source
from mhtrack.sources.recording import AsterixSource

from .conftest import differences

N_BLOCKS, PER_BLOCK, RADAR, DT = 20, 3, 258, 0.5


#: Twenty CAT048 blocks of three plots each from radar SAC 1 / SIC 2, plot ``i`` at
#: ``i · DT`` s (block ``k`` holds plots ``3k … 3k + 2``).
BLOCKS = plot_blocks(N_BLOCKS, PER_BLOCK, dt=DT, sensor=RADAR, max_range=9e4)
STARTS = np.cumsum([0] + [len(b) for b in BLOCKS]).tolist()


@pytest.fixture(scope="module")
def sensors(tmp_path_factory: pytest.TempPathFactory) -> SensorSet:
    path = tmp_path_factory.mktemp("raw_damage") / "sensors.toml"
    radar = RadarSensor(RADAR, "polar", pd=0.9, lat=45.0, lon=16.0, sigma_range=40.0,
                        sigma_bearing_deg=0.05, period=4.0)
    write_sensors(SensorSet(None, (radar,)), path)
    return read_sensors(path)


def _both(path: Path, sensors: SensorSet) -> tuple[list[Scan], list[Scan], AsterixSource]:
    """The frames of the convert path and of ``track``'s source; the file rows and the
    skip lines of both are equal (asserted here)."""
    with tempfile.TemporaryDirectory() as tmp:
        table = recording_table(path, sensors, Path(tmp))
        ref = list(table.scans())
    src = open_source(path, sensors=sensors)
    assert isinstance(src, AsterixSource)
    got = list(src)
    rows = np.concatenate([s.rows for s in got])
    assert np.array_equal(src.file_rows(rows), table.file_row[rows])
    assert src.problems.lines(src.name) == read_recording(path).problems.lines(str(path))
    return ref, got, src


def _times(frames: list[Scan]) -> list[float]:
    return sorted(float(t) for s in frames for t in s.t)


def _plots_of(blocks: list[int]) -> list[float]:
    """The times of the plots of these blocks (module docstring)."""
    return sorted(DT * (PER_BLOCK * k + j) for k in blocks for j in range(PER_BLOCK))


def _length(data: bytearray, k: int, length: int) -> None:
    data[STARTS[k] + 1:STARTS[k] + 3] = length.to_bytes(2, "big")


def _hand_made(case: str) -> tuple[bytes, list[int]]:
    """A damaged stream and the blocks that must survive it (``"all"``: the four
    damages, each more than :data:`~mhtrack.io.asterix.resync.CONFIRM` blocks from the
    next, so that reading resumes between them)."""
    data = bytearray(b"".join(BLOCKS))
    everything = list(range(N_BLOCKS))
    if case == "length":  # block 3's length covers blocks 4 and 5 exactly
        _length(data, 3, STARTS[6] - STARTS[3])
        return bytes(data), [k for k in everything if k != 3]
    if case == "category":  # block 6's category 48 -> 49, which libasterix does not carry
        data[STARTS[6]] ^= 1
        return bytes(data), [k for k in everything if k != 6]
    # a CAT048 header of 7 octets whose record announces no item: framed like a block
    garbage = bytes([48, 0, 7, 0, 0, 0, 0])
    if case == "garbage":
        return bytes(data[:STARTS[8]]) + garbage + bytes(data[STARTS[8]:]), everything
    if case == "cut":
        return bytes(data[:STARTS[10] + 5]), list(range(10))
    _length(data, 3, STARTS[6] - STARTS[3])
    data[STARTS[9]] ^= 1
    return (bytes(data[:STARTS[13]]) + garbage + bytes(data[STARTS[13]:STARTS[18] + 5]),
            [k for k in range(18) if k not in (3, 9)])


@pytest.mark.parametrize("case", ["length", "category", "garbage", "cut", "all"])
def test_hand_made_damage(sensors: SensorSet, tmp_path: Path, case: str) -> None:
    data, survivors = _hand_made(case)
    path = tmp_path / "damaged.ast"
    path.write_bytes(data)
    ref, got, src = _both(path, sensors)
    assert differences(ref, got) == []
    assert _times(got) == _plots_of(survivors)
    assert src.stats.skipped  # the damage is said, in the lines compared above
    first = src.problems.first.get("resync")
    damaged = {"length": STARTS[3], "category": STARTS[6], "garbage": STARTS[8],
               "cut": STARTS[10], "all": STARTS[3]}[case]
    assert first == damaged, src.problems.lines(src.name)


def _damage(draw: st.DrawFn) -> bytes:
    """The stream with one seeded damage: a cut, octets of a block header or length
    flipped, random octets inserted (between blocks or anywhere), octets deleted."""
    data = bytearray(b"".join(BLOCKS))
    kind = draw(st.sampled_from(["cut", "header", "insert", "between", "delete"]))
    if kind == "cut":
        return bytes(data[:draw(st.integers(1, len(data) - 1))])
    if kind == "header":
        k = draw(st.integers(0, N_BLOCKS - 1))
        for octet in draw(st.sets(st.integers(0, 2), min_size=1)):
            data[STARTS[k] + octet] ^= draw(st.integers(1, 255))
        return bytes(data)
    if kind == "delete":
        a = draw(st.integers(0, len(data) - 1))
        return bytes(data[:a] + data[a + draw(st.integers(1, 40)):])
    at = STARTS[draw(st.integers(1, N_BLOCKS - 1))] if kind == "between" else \
        draw(st.integers(0, len(data)))
    return bytes(data[:at]) + draw(st.binary(min_size=1, max_size=40)) + bytes(data[at:])


@settings(derandomize=True, deadline=None, max_examples=60, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.data())
def test_track_reads_a_damaged_raw_stream_as_convert_does(
        sensors: SensorSet, tmp_path: Path, data: st.DataObject) -> None:
    path = tmp_path / "damaged.ast"
    path.write_bytes(data.draw(st.composite(lambda draw: _damage(draw))()))
    try:
        decoded = len(read_recording(path))
    except InputError as e:  # not a recording: track refuses it with the same line
        with pytest.raises(InputError) as got:
            list(open_source(path, sensors=sensors))
        assert str(got.value) == str(e)
        return
    if decoded == 0:  # nothing to track: refused, one line naming the file
        with pytest.raises(InputError, match=r"damaged\.ast: no plot"):
            list(open_source(path, sensors=sensors))
        return
    ref, got, _ = _both(path, sensors)
    assert differences(ref, got) == []


@pytest.mark.parametrize("suffix", [".raw", ".ast"])
def test_not_a_recording_refused_alike(sensors: SensorSet, tmp_path: Path,
                                       suffix: str) -> None:
    """A file that is no ASTERIX (text) named like a raw recording: ``convert`` and
    ``track`` end with status 2 and the same one line naming the file and byte 0."""
    path = tmp_path / f"notes{suffix}"
    path.write_text("this is not a recording\n" * 20)
    write_sensors(sensors, tmp_path / "s.toml")
    runner = CliRunner()
    c = runner.invoke(cli, ["convert", str(path), "--out", str(tmp_path / "p.csv")])
    t = runner.invoke(cli, ["track", str(path), "--sensors", str(tmp_path / "s.toml"),
                            "--out", str(tmp_path / "t.csv")])
    assert c.exit_code == t.exit_code == 2, (c.output, t.output)
    line = f"{path}: byte 0: not an ASTERIX recording"
    assert [x for x in c.output.splitlines() if line in x] == \
        [x for x in t.output.splitlines() if line in x] != []


@pytest.mark.parametrize("case", ["length", "category", "garbage"])
def test_unnamed_raw_stream_with_a_damaged_first_block(sensors: SensorSet, tmp_path: Path,
                                                       case: str) -> None:
    """A raw recording under a name that says nothing (``.dat``) whose first block is
    damaged — its length covering blocks 1 and 2, its category flipped, or garbage
    framed like a block before it — is sniffed as a recording by the reading path
    (:func:`~mhtrack.io.asterix.api.is_recording`: any block found in the first 64
    KiB), and ``track`` reads it as ``convert`` does (before, the first two were taken
    for a plots table and refused: ``unknown file type ('.dat')``)."""
    from mhtrack.io.asterix import is_recording

    data = bytearray(b"".join(BLOCKS))
    if case == "length":
        _length(data, 0, STARTS[3])
    elif case == "category":
        data[0] ^= 1
    else:
        data[:0] = bytes([48, 0, 7, 0, 0, 0, 0])
    path = tmp_path / "feed.dat"
    path.write_bytes(bytes(data))
    assert is_recording(path)
    ref, got, src = _both(path, sensors)  # the convert path's frames, and track's
    assert differences(ref, got) == []
    assert _times(got) == _plots_of(range(1 if case != "garbage" else 0, N_BLOCKS))
    assert src.problems.first.get("resync") == 0
    write_sensors(sensors, tmp_path / "s.toml")
    r = CliRunner().invoke(cli, ["track", str(path), "--sensors", str(tmp_path / "s.toml"),
                                 "--out", str(tmp_path / "t.csv"), "-q"])
    assert r.exit_code == 0, r.output


def test_tables_and_noise_are_classified_as_before(sensors: SensorSet,
                                                   tmp_path: Path) -> None:
    """A real plots table (``convert``'s CSV and Parquet) is no recording, under its own
    name or ``.dat``; random bytes that start like a raw data block but hold none are no
    recording either, and ``track`` refuses them with the one line it always did."""
    from mhtrack.io.asterix import is_recording

    rec = tmp_path / "rec.ast"
    rec.write_bytes(b"".join(BLOCKS))
    runner = CliRunner()
    for name in ("plots.csv", "plots.parquet"):
        r = runner.invoke(cli, ["convert", str(rec), "--out", str(tmp_path / name), "-q"])
        assert r.exit_code == 0, r.output
        alias = tmp_path / f"{name.replace('.', '_')}.dat"
        alias.write_bytes((tmp_path / name).read_bytes())
        assert not is_recording(tmp_path / name) and not is_recording(alias), name
    noise = tmp_path / "noise.dat"  # category 48, a length that fits: framed, no records
    noise.write_bytes(bytes([48, 0, 16]) + np.random.default_rng(3).bytes(997))
    assert not is_recording(noise)
    write_sensors(sensors, tmp_path / "s.toml")
    r = runner.invoke(cli, ["track", str(noise), "--sensors", str(tmp_path / "s.toml"),
                            "--out", str(tmp_path / "t.csv")])
    assert r.exit_code == 2
    assert r.output.strip().splitlines() == [
        f"Error: {noise}: unknown file type ('.dat'); use a .csv or .parquet file"]
