"""Malformed inputs: each must raise InputError whose message names the file, the line
(CSV, header = line 1) or 0-based row (Parquet), and the column — checked verbatim."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from mhtrack.io import (
    InputError,
    read_plots,
    read_toml,
    read_tracks,
    read_truth,
    write_plots,
    write_scenario_toml,
    write_tracks,
)
from mhtrack.models.sensors import CartesianSensor, PolarRadar
from mhtrack.records import PlotTable, TrackTable

P = "scan,time,sensor,x,y\n"
G = "scan,time,target_id,x,y,vx,vy\n"
T = "scan,time,track_id,x,y,vx,vy,plot\n"
PRB = "scan,time,sensor,x,y,range,bearing\n"
REG = {0: CartesianSensor(0), 1: PolarRadar(1), 2: PolarRadar(2)}

# (id, reader, sensors, file text, expected message with {f} for the file name)
CSV_CASES = [
    ("nan", read_plots, None, P + "1,0,0,1,2\n1,0,0,nan,2\n",
     "{f}, line 3, column 'x': value 'nan' is not finite"),
    ("NaN-text-kept", read_plots, None, P + "1,0,0,1,NaN\n",
     "{f}, line 2, column 'y': value 'NaN' is not finite"),
    ("inf", read_truth, None, G + "1,0,3,1,2,3,4\n2,1,3,1,2,-inf,4\n",
     "{f}, line 3, column 'vx': value '-inf' is not finite"),
    ("missing-columns", read_plots, None, "scan,time,x\n1,0,5\n",
     "{f}: missing required column(s) 'sensor', 'y' (plots files need scan, time, "
     "sensor, x, y; found 'scan', 'time', 'x')"),
    ("missing-plot-column", read_tracks, None, "scan,time,track_id,x,y,vx,vy\n",
     "{f}: missing required column(s) 'plot' (tracks files need scan, time, track_id, "
     "x, y, vx, vy, plot; found 'scan', 'time', 'track_id', 'x', 'y', 'vx', 'vy')"),
    ("text-in-number", read_tracks, None, T + "1,0,1,1,2,3,4,\n1,0,2,abc,2,3,4,0\n",
     "{f}, line 3, column 'x': value 'abc' is not a number"),
    ("non-integer-scan", read_plots, None, P + "1,0,0,1,2\n1.5,0,0,1,2\n",
     "{f}, line 3, column 'scan': value '1.5' is not an integer"),
    ("non-integer-sensor", read_plots, None, P + "1,0,A,1,2\n",
     "{f}, line 2, column 'sensor': value 'A' is not an integer"),
    ("non-integer-id", read_truth, None, G + "1,0,3e0,1,2,3,4\n",
     "{f}, line 2, column 'target_id': value '3e0' is not an integer"),
    ("empty-cell", read_plots, None, P + "1,0,0,,2\n",
     "{f}, line 2, column 'x': value is missing"),
    ("time-backwards", read_plots, None, P + "1,5,0,1,2\n1,5,0,1,2\n2,4.5,0,1,2\n",
     "{f}, line 4, column 'time': time goes backwards: 4.5 at scan 2 after 5.0 at scan 1 "
     "(line 3)"),
    ("two-times-in-scan", read_truth, None, G + "1,0,3,1,2,3,4\n1,0.25,4,1,2,3,4\n",
     "{f}, line 3, column 'time': time 0.25 differs from time 0.0 of scan 1 on line 2; "
     "all rows of a scan must have the same time"),
    ("decreasing-scan", read_plots, None, P + "1,0,0,1,2\n3,2,0,1,2\n2,1,0,1,2\n",
     "{f}, line 4, column 'scan': scan 2 after scan 3 (line 3); rows must be in "
     "non-decreasing scan order"),
    ("unknown-sensor", read_plots, REG, P + "1,0,0,1,2\n1,0,7,1,2\n",
     "{f}, line 3, column 'sensor': unknown sensor 7 (known sensors: 0, 1, 2)"),
    ("empty-file", read_plots, None, "",
     "{f}: file is empty"),
    ("blank-lines-only", read_truth, None, "\n\n",
     "{f}: file is empty (no header line)"),
    ("header-only-plots", read_plots, None, P,
     "{f}: no rows (a plots file needs at least one plot)"),
    ("duplicate-target", read_truth, None,
     G + "1,0,3,1,2,3,4\n1,0,5,1,2,3,4\n2,1,3,1,2,3,4\n2,1,3,1,2,3,4\n",
     "{f}, line 5, column 'target_id': target_id 3 appears twice in scan 2 (also on line 4)"),
    ("duplicate-track", read_tracks, None, T + "1,0,9,1,2,3,4,\n1,0,4,1,2,3,4,\n1,0,9,1,2,3,4,0\n",
     "{f}, line 4, column 'track_id': track_id 9 appears twice in scan 1 (also on line 2)"),
    ("truth-id-order", read_truth, None, G + "1,0,5,1,2,3,4\n1,0,3,1,2,3,4\n",
     "{f}, line 3, column 'target_id': target_id 3 after 5 in scan 1; rows of a scan must "
     "be in increasing target_id order"),
    ("negative-target-id", read_truth, None, G + "1,0,-1,1,2,3,4\n",
     "{f}, line 2, column 'target_id': target_id -1 is negative"),
    ("negative-plot", read_tracks, None, T + "1,0,1,1,2,3,4,\n2,1,1,1,2,3,4,-1\n",
     "{f}, line 3, column 'plot': plot index -1 is negative (leave the cell empty for a "
     "miss)"),
    ("score-nan", read_tracks, None, T[:-1] + ",score\n1,0,1,1,2,3,4,,nan\n",
     "{f}, line 2, column 'score': value 'nan' is not finite"),
    ("tentative-not-a-flag", read_tracks, None,
     T[:-1] + ",tentative\n1,0,1,1,2,3,4,,1\n2,1,1,1,2,3,4,,2\n",
     "{f}, line 3, column 'tentative': tentative must be 0 or 1, got 2"),
    ("blank-lines-counted", read_plots, None, "\n" + P + "1,0,0,1,2\n\n\n1,0,0,inf,2\n",
     "{f}, line 6, column 'x': value 'inf' is not finite"),
    ("crlf", read_plots, None, (P + "1,0,0,1,2\n1,0,0,x,2\n").replace("\n", "\r\n"),
     "{f}, line 3, column 'x': value 'x' is not a number"),
    ("too-many-fields", read_plots, None, P + "1,0,0,1,2\n1,0,0,1,2,9\n",
     "{f}, line 3: expected 5 comma-separated fields, found 6"),
    ("too-few-fields", read_plots, None, P + "1,0,0,1\n",
     "{f}, line 2: expected 5 comma-separated fields, found 4"),
    ("duplicate-header", read_plots, None, "scan,time,sensor,x,y,x\n1,0,0,1,2,3\n",
     "{f}, column 'x': appears twice in the header"),
    ("origin-invalid", read_plots, None, P[:-1] + ",origin\n1,0,0,1,2,-2\n",
     "{f}, line 2, column 'origin': origin -2 is invalid (a target id >= 0, or -1 for "
     "clutter)"),
    ("range-without-bearing", read_plots, None, P[:-1] + ",range\n1,0,0,1,2,3\n",
     "{f}: column 'range' is present without column 'bearing'; give both or neither"),
    ("range-empty-no-registry", read_plots, None, PRB + "1,0,1,1,2,100,10\n1,0,0,1,2,,\n",
     "{f}, line 3, column 'range': value is missing (range and bearing may be empty only "
     "on rows of Cartesian sensors, when a sensor registry is given)"),
    ("range-empty-polar", read_plots, REG, PRB + "1,0,0,1,2,,\n1,0,2,1,2,100,\n",
     "{f}, line 3, column 'bearing': value is missing (sensor 2 is a polar radar)"),
    ("range-nan-polar", read_plots, REG, PRB + "1,0,0,1,2,nan,nan\n1,0,1,1,2,NaN,3\n",
     "{f}, line 3, column 'range': value 'NaN' is not finite"),
    ("range-inf-cartesian", read_plots, REG, PRB + "1,0,0,1,2,inf,1\n",
     "{f}, line 2, column 'range': value 'inf' is not finite"),
    ("range-negative", read_plots, REG, PRB + "1,0,1,1,2,100,3\n1,0,1,1,2,-5,3\n",
     "{f}, line 3, column 'range': range -5.0 is negative"),
    ("range-overflows", read_plots, REG, PRB + "1,0,1,1,2,1e200,3\n",
     "{f}, line 2, column 'range': value 1e200 is out of range (expected a finite number "
     "in [-1e15, 1e15])"),
    ("polar-needs-range", read_plots, REG, P + "1,0,0,1,2\n1,0,2,1,2\n",
     "{f}: missing column(s) 'range', 'bearing', needed by polar sensor(s) 2"),
    ("equal-times", read_plots, None, P + "79,79,0,1,2\n80,79,0,1,2\n",
     "{f}, line 3, column 'time': scan 80 has time 79.0 s, not after scan 79's (line 2); "
     "times must strictly increase with scan number"),
    ("equal-times-truth", read_truth, None, G + "1,0,3,1,2,3,4\n2,0,3,1,2,3,4\n",
     "{f}, line 3, column 'time': scan 2 has time 0.0 s, not after scan 1's (line 2); "
     "times must strictly increase with scan number"),
    ("scan-gap", read_plots, None, P + "50,50,0,1,2\n50,50,0,1,2\n1000051,51,0,1,2\n",
     "{f}, line 4, column 'scan': scan 1000051 follows scan 50 (line 3): the 1000000 scan "
     "numbers between them would each be tracked as an empty scan, more than the 10000 "
     "allowed in one gap; renumber the scans"),
    ("scan-gap-index-extremes", read_plots, None,
     P + f"{-2**53},0,0,1,2\n{2**53},1,0,1,2\n",
     "{f}, line 3, column 'scan': scan 9007199254740992 follows scan "
     "-9007199254740992 (line 2): the 18014398509481983 scan numbers between them "
     "would each be tracked as an empty scan, more than the 10000 allowed in one gap; "
     "renumber the scans"),
    ("scan-beyond-2^53", read_plots, None, P + f"{2**53 + 1},0,0,1,2\n",
     "{f}, line 2, column 'scan': value 9007199254740993 is out of range (expected an "
     "integer in [-2^53, 2^53])"),
    ("scan-beyond-int64", read_plots, None, P + f"{10**20},0,0,1,2\n",
     "{f}, line 2, column 'scan': value 100000000000000000000 is out of range (expected an "
     "integer in [-2^53, 2^53])"),
    ("scan-int64-min", read_plots, None, P + f"{-2**63},0,0,1,2\n",
     "{f}, line 2, column 'scan': value -9223372036854775808 is out of range (expected an "
     "integer in [-2^53, 2^53])"),
    ("time-1e308", read_plots, None, P + "1,1e308,0,1,2\n",
     "{f}, line 2, column 'time': value 1e308 is out of range (expected a finite number in "
     "[-1e12, 1e12])"),
    ("scan-gaps-total", read_plots, None,
     P + "".join(f"{k * 5001},{k},0,1,2\n" for k in range(4)),
     "{f}, line 3, column 'scan': the file has 4 scans with plots but 15000 scan numbers "
     "without any, more than the 10000 allowed (max(10000, 10 × scans with plots)); the "
     "largest gap: scan 5001 follows scan 0 (line 2): the 5000 scan numbers between them "
     "would each be tracked as an empty scan; renumber the scans"),
    ("cr-only-line-ends", read_plots, None, (P + "1,0,0,1,2\n\n1,0,0,x,2\n").replace("\n", "\r"),
     "{f}, line 4, column 'x': value 'x' is not a number"),
]  # fmt: skip


@pytest.mark.parametrize(
    ("reader", "sensors", "text", "message"),
    [c[1:] for c in CSV_CASES],
    ids=[c[0] for c in CSV_CASES],
)
def test_malformed_csv(tmp_path: Path, reader, sensors, text: str, message: str) -> None:
    path = tmp_path / "input.csv"
    path.write_bytes(text.encode())
    kwargs = {} if sensors is None else {"sensors": sensors}
    with pytest.raises(InputError) as info:
        reader(path, **kwargs)
    assert str(info.value) == message.format(f=path)
    assert info.value.file == str(path)


def test_gap_of_max_gap_empty_scans_is_accepted(tmp_path: Path) -> None:
    from mhtrack.io.plots import MAX_GAP

    path = tmp_path / "plots.csv"
    path.write_text(P + f"1,1,0,1,2\n{MAX_GAP + 2},2,0,1,2\n")
    assert read_plots(path).n_scans == MAX_GAP + 2


def test_cr_only_line_ends_read_like_lf(tmp_path: Path) -> None:
    text = "\ufeff" + P + "1,0,0,1,2\n\n2,1,0,3,4\n"
    (tmp_path / "lf.csv").write_text(text, newline="")
    (tmp_path / "cr.csv").write_text(text.replace("\n", "\r"), newline="")
    a, b = read_plots(tmp_path / "lf.csv"), read_plots(tmp_path / "cr.csv")
    for name in ("scan", "time", "sensor", "x", "y"):
        assert np.array_equal(getattr(a, name), getattr(b, name))


@pytest.mark.parametrize(("line", "column"), [(3, "scan"), (4, "y")])
def test_invalid_utf8_names_file_line_and_column(tmp_path: Path, line: int, column: str) -> None:
    lines = [P.encode()[:-1], b"1,0,0,1,2", b"2,1,0,1,2", b"2,1,0,1,2"]
    if column == "scan":
        lines[line - 1] = b"2\xff,1,0,1,2"
    else:
        lines[line - 1] = b"2,1,0,1,2\xff"
    path = tmp_path / "plots.csv"
    path.write_bytes(b"\n".join(lines) + b"\n")
    with pytest.raises(InputError) as info:
        read_plots(path)
    assert str(info.value) == (
        f"{path}, line {line}, column {column!r}: not valid UTF-8 text (byte 0xff)"
    )


def test_plots_checked_against_scenario_scans(tmp_path: Path) -> None:
    from mhtrack.io.plots import check_scan_times

    path = tmp_path / "plots.csv"
    path.write_text(P + "1,1,0,1,2\n2,2,0,1,2\n5,5,0,1,2\n")
    table = read_plots(path)
    scans, times = np.arange(1, 6), np.arange(1, 6) * 1.0
    check_scan_times(path, table, scans, times, "scenario s.toml")
    check_scan_times(path, table, scans, times * (1 + 1e-9), "scenario s.toml")
    with pytest.raises(InputError) as info:
        check_scan_times(path, table, scans[:4], times[:4], "scenario s.toml")
    assert str(info.value) == (
        f"{path}, line 4, column 'scan': scan 5 is not a scan of scenario s.toml (scans 1 "
        "to 4); 1 row(s) are outside it"
    )
    with pytest.raises(InputError) as info:
        check_scan_times(path, table, scans, times * 10, "scenario s.toml")
    assert str(info.value) == (
        f"{path}, line 2, column 'time': scan 1 has time 1.0 s, but scenario s.toml gives "
        "10.0 s for it; the plots' times must match the scenario's k·T"
    )


def test_error_attributes_locate_the_cell(tmp_path: Path) -> None:
    path = tmp_path / "plots.csv"
    path.write_text(P + "1,0,0,1,2\n\n1,0,0,1,nan\n")
    with pytest.raises(InputError) as info:
        read_plots(path)
    e = info.value
    assert (e.file, e.line, e.row, e.column) == (str(path), 4, 1, "y")


def test_header_only_tracks_and_truth_are_valid(tmp_path: Path) -> None:
    (tmp_path / "t.csv").write_text(T)
    (tmp_path / "g.csv").write_text(G)
    assert len(read_tracks(tmp_path / "t.csv")) == 0
    assert len(read_truth(tmp_path / "g.csv")) == 0


@pytest.mark.parametrize("reader", [read_plots, read_truth, read_tracks])
def test_nonexistent_path(tmp_path: Path, reader) -> None:
    path = tmp_path / "nope" / "file.csv"
    with pytest.raises(InputError) as info:
        reader(path)
    assert str(info.value) == f"{path}: no such file"


def test_directory_and_unknown_extension(tmp_path: Path) -> None:
    d = tmp_path / "dir.parquet"
    d.mkdir()
    with pytest.raises(InputError) as info:
        read_truth(d)
    assert str(info.value) == f"{d}: is a directory, not a file"
    txt = tmp_path / "plots.txt"
    txt.write_text(P + "1,0,0,1,2\n")
    with pytest.raises(InputError) as info:
        read_plots(txt)
    assert str(info.value) == f"{txt}: unknown file type ('.txt'); use a .csv or .parquet file"


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their mode")
def test_unreadable_file(tmp_path: Path) -> None:
    path = tmp_path / "plots.csv"
    path.write_text(P + "1,0,0,1,2\n")
    path.chmod(0)
    with pytest.raises(InputError) as info:
        read_plots(path)
    assert str(info.value) == f"{path}: cannot read (Permission denied)"


def test_writers_name_the_file(tmp_path: Path) -> None:
    table = PlotTable(*(np.zeros(1, t) for t in (np.int64, float, np.int64, float, float)))
    with pytest.raises(InputError) as info:
        write_plots(table, tmp_path / "plots.xlsx")
    assert str(info.value).startswith(f"{tmp_path / 'plots.xlsx'}: unknown file type ('.xlsx')")
    missing_dir = tmp_path / "no" / "tracks.csv"
    with pytest.raises(InputError) as info:
        write_tracks(TrackTable.empty(), missing_dir)
    assert str(info.value) == f"{missing_dir}: cannot write (No such file or directory)"


# -- Parquet: rows are 0-based ----------------------------------------------------------


def plots_columns(**override: pa.Array) -> dict[str, pa.Array]:
    cols = {
        "scan": pa.array([1, 1, 2], pa.int64()),
        "time": pa.array([0.0, 0.0, 1.0]),
        "sensor": pa.array([0, 0, 0], pa.int64()),
        "x": pa.array([1.0, 2.0, 3.0]),
        "y": pa.array([4.0, 5.0, 6.0]),
    }
    return cols | override


def tracks_columns(**override: pa.Array) -> dict[str, pa.Array]:
    f = pa.array([0.0, 0.0, 0.0])
    cols = {
        "scan": pa.array([1, 1, 2], pa.int64()),
        "time": pa.array([0.0, 0.0, 1.0]),
        "track_id": pa.array([1, 2, 1], pa.int64()),
        "x": f, "y": f, "vx": f, "vy": f,
        "plot": pa.array([0, None, 4], pa.int64()),
    }  # fmt: skip
    return cols | override


PARQUET_CASES = [
    ("nan", read_plots, plots_columns(x=pa.array([1.0, 2.0, np.nan])),
     "{f}, row 2 (0-based), column 'x': value 'nan' is not finite"),
    ("null", read_plots, plots_columns(y=pa.array([1.0, None, 2.0])),
     "{f}, row 1 (0-based), column 'y': value is missing"),
    ("text-column", read_plots, plots_columns(x=pa.array(["1", "2", "a"])),
     "{f}, column 'x': has type string, expected numbers"),
    ("float-scan", read_plots, plots_columns(scan=pa.array([1.0, 1.0, 2.5])),
     "{f}, row 2 (0-based), column 'scan': value '2.5' is not an integer"),
    ("decreasing-scan", read_plots, plots_columns(scan=pa.array([2, 2, 1], pa.int64())),
     "{f}, row 2 (0-based), column 'scan': scan 1 after scan 2 (row 1); rows must be in "
     "non-decreasing scan order"),
    ("no-rows", read_plots, {k: v[:0] for k, v in plots_columns().items()},
     "{f}: no rows (a plots file needs at least one plot)"),
    ("negative-plot", read_tracks, tracks_columns(plot=pa.array([0, -3, None], pa.int64())),
     "{f}, row 1 (0-based), column 'plot': plot index -3 is negative (use null for a miss)"),
    ("duplicate-track", read_tracks, tracks_columns(track_id=pa.array([2, 2, 1], pa.int64())),
     "{f}, row 1 (0-based), column 'track_id': track_id 2 appears twice in scan 1 "
     "(also on row 0)"),
    ("missing-column", read_tracks, {k: v for k, v in tracks_columns().items() if k != "vy"},
     "{f}: missing required column(s) 'vy' (tracks files need scan, time, track_id, x, y, "
     "vx, vy, plot; found 'scan', 'time', 'track_id', 'x', 'y', 'vx', 'plot')"),
]  # fmt: skip


@pytest.mark.parametrize(
    ("reader", "columns", "message"),
    [c[1:] for c in PARQUET_CASES],
    ids=[c[0] for c in PARQUET_CASES],
)
def test_malformed_parquet(tmp_path: Path, reader, columns, message: str) -> None:
    path = tmp_path / "input.parquet"
    pq.write_table(pa.table(columns), path)
    with pytest.raises(InputError) as info:
        reader(path)
    assert str(info.value) == message.format(f=path)


def test_not_a_parquet_file(tmp_path: Path) -> None:
    path = tmp_path / "plots.parquet"
    path.write_text(P + "1,0,0,1,2\n")
    with pytest.raises(InputError) as info:
        read_plots(path)
    assert str(info.value).startswith(f"{path}: not a readable Parquet file (")


def test_parquet_accepts_other_number_types(tmp_path: Path) -> None:
    """int32 ids, float32 positions, and a float ``plot`` column with null misses (as pandas
    writes an integer column with missing values) are read into the int64/float64 table."""
    path = tmp_path / "tracks.parquet"
    cols = tracks_columns(
        track_id=pa.array([1, 2, 1], pa.int32()),
        x=pa.array([0.5, 1.5, 2.5], pa.float32()),
        plot=pa.array([3.0, None, 0.0]),
    )
    pq.write_table(pa.table(cols), path)
    t = read_tracks(path)
    assert t.track_id.dtype == np.int64
    assert t.track_id.tolist() == [1, 2, 1]
    assert t.x.tolist() == [0.5, 1.5, 2.5]
    assert t.plot.tolist() == [3, -1, 0]
    pq.write_table(pa.table(tracks_columns(plot=pa.array([3.0, np.nan, 0.0]))), path)
    with pytest.raises(InputError, match=r"row 1 \(0-based\), column 'plot': value 'nan' is not"):
        read_tracks(path)


# -- TOML -------------------------------------------------------------------------------


def test_toml_syntax_error_names_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "scenario.toml"
    path.write_text('name = "crossing"\n\n[region]\nxmin -4000\n')
    with pytest.raises(InputError) as info:
        read_toml(path)
    assert str(info.value) == (
        f"{path}, line 4, column 6: Expected '=' after a key in a key/value pair"
    )
    assert info.value.line == 4


def test_toml_unterminated_and_missing_and_bad_utf8(tmp_path: Path) -> None:
    path = tmp_path / "s.toml"
    path.write_text('a = "open\n')
    with pytest.raises(InputError, match=rf"^{path}, line 1, column 10: "):
        read_toml(path)
    with pytest.raises(InputError) as info:
        read_toml(tmp_path / "none.toml")
    assert str(info.value) == f"{tmp_path / 'none.toml'}: no such file"
    path.write_bytes(b'a = 1\nb = "\xff"\n')
    with pytest.raises(InputError) as info:
        read_toml(path)
    assert str(info.value) == f"{path}, line 2: not valid UTF-8 text (byte 0xff)"


def test_toml_none_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"scenario key 'clutter\.rate' is None"):
        write_scenario_toml({"clutter": {"rate": None}}, tmp_path / "s.toml")
    assert not (tmp_path / "s.toml").exists()


def test_plot_coordinates_beyond_the_trackers_bound_are_located(tmp_path: Path) -> None:
    p = tmp_path / "plots.csv"
    p.write_text("scan,time,sensor,x,y\n1,1,0,0,0\n1,1,0,2e9,0\n2,2,0,0,0\n")
    with pytest.raises(InputError, match=r"line 3.*'x'.*beyond ±1e\+09 m"):
        read_plots(p)
