"""Property: any plots, tracks, truth or timed-plots file either loads or raises
:class:`~mhtrack.errors.InputError` — never another exception. Inputs: arbitrary bytes,
valid files with one cell replaced by arbitrary text, and Parquet files of arbitrary
column types."""

from __future__ import annotations

import contextlib
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mhtrack.errors import InputError
from mhtrack.io import read_plots, read_tracks, read_truth
from mhtrack.models.radars import RadarSensor, SensorSet

PLOTS = "scan,time,sensor,x,y,origin\n1,1.0,0,10.5,-3,1\n1,1.0,0,7,8,-1\n3,3.5,0,1e3,2,-1\n"
TRUTH = "scan,time,target_id,x,y,vx,vy\n1,1.0,0,1,2,3,4\n1,1.0,4,1,2,3,4\n2,2.0,0,5,6,7,8\n"
TRACKS = ("scan,time,track_id,x,y,vx,vy,plot,score\n1,1.0,3,1,2,3,4,0,1.5\n"
          "2,2.0,3,1,2,3,4,,2.5\n2,2.0,1,0,0,0,0,2,0.1\n")
TIMED = "time,sensor,range,bearing\n0.5,1,1000,10\n0.7,1,2000,20\n1.9,1,1500,30\n"
SENSORS = SensorSet((52.0, 4.0), (RadarSensor(1, "polar", pd=0.9, position=(0.0, 0.0),
                                       sigma_range=50.0, sigma_bearing_deg=0.5,
                                       period=2.0),))

#: Derandomized (same examples every run), no deadline (the machine is shared).
FUZZ = settings(derandomize=True, deadline=None, max_examples=80, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])

READERS: dict[str, tuple[str, Callable[[Path], Any]]] = {
    "plots": (PLOTS, read_plots),
    "truth": (TRUTH, read_truth),
    "tracks": (TRACKS, read_tracks),
    "timed": (TIMED, lambda p: read_plots(p, SENSORS)),
}

cells = st.one_of(
    st.text(max_size=30),
    st.sampled_from(["", "nan", "inf", "-inf", "1e308", "-1e309", "9007199254740993",
                     str(2**63), str(-(2**64)), "1e20", "0x10", '"', '""', "1,2", "\r",
                     "\n", "\x00", "1_000", " 1", "١", "2e9", "-1", "NaN", "true"]),
    st.integers().map(str),
    st.floats().map(repr),
)


def _load(reader: Callable[[Path], Any], path: Path) -> None:
    try:
        reader(path)
    except InputError as e:
        text = str(e)
        assert "\n" not in text.rstrip("\n") or "\n" in path.name, text
        assert text.startswith(str(path)), text


@pytest.fixture(scope="module")
def folder() -> Any:
    d = Path(tempfile.mkdtemp(prefix="mhtrack-fuzz-"))
    yield d
    shutil.rmtree(d, ignore_errors=True)


@pytest.mark.parametrize("kind", sorted(READERS))
@FUZZ
@given(data=st.binary(max_size=300))
def test_any_bytes_load_or_raise_input_error(folder: Path, kind: str, data: bytes) -> None:
    path = folder / f"{kind}.csv"
    path.write_bytes(data)
    _load(READERS[kind][1], path)


@pytest.mark.parametrize("kind", sorted(READERS))
@FUZZ
@given(where=st.tuples(st.integers(0, 3), st.integers(0, 8)), cell=cells)
def test_one_bad_cell_loads_or_raises_input_error(folder: Path, kind: str,
                                                  where: tuple[int, int], cell: str) -> None:
    text, reader = READERS[kind]
    lines = [line.split(",") for line in text.splitlines()]
    row = lines[where[0] % len(lines)]
    row[where[1] % len(row)] = cell
    path = folder / f"{kind}-cell.csv"
    path.write_text("\n".join(",".join(r) for r in lines) + "\n")
    _load(reader, path)


arrow_columns = st.sampled_from([
    pa.int8(), pa.int64(), pa.uint64(), pa.float16(), pa.float32(), pa.float64(), pa.string(),
    pa.bool_(), pa.timestamp("ns"), pa.timestamp("s", tz="UTC"), pa.list_(pa.int64()),
    pa.null(), pa.binary(), pa.date32(), pa.decimal128(10, 2)])


@pytest.mark.parametrize("kind", sorted(READERS))
@FUZZ
@given(types=st.lists(arrow_columns, min_size=8, max_size=8), seed=st.integers(0, 2**16),
       n=st.integers(0, 4))
def test_parquet_of_any_column_types_loads_or_raises_input_error(
        folder: Path, kind: str, types: list[pa.DataType], seed: int, n: int) -> None:
    text, reader = READERS[kind]
    names = text.splitlines()[0].split(",")
    rng = np.random.default_rng(seed)
    columns = {}
    for name, t in zip(names, types, strict=False):
        raw = rng.choice([0, 1, -1, 2**60, 1e300, np.nan, 3.5], size=n).tolist()
        try:
            columns[name] = pa.array(raw, type=pa.float64()).cast(t, safe=False)
        except (pa.ArrowInvalid, pa.ArrowNotImplementedError, pa.ArrowTypeError):
            columns[name] = pa.nulls(n, type=t)
    path = folder / f"{kind}.parquet"
    pq.write_table(pa.table(columns), path)
    with contextlib.suppress(InputError):
        reader(path) if kind != "timed" else read_plots(path, SENSORS)
