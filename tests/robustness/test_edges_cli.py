"""Issue 16's hostile inputs, each through the CLI: exit status 2, one line on stderr that
names the file and the line/field (or the option) and the expected range, no traceback,
the input left byte for byte. And a property over every number option of every command:
any text is either a number within the option's documented range or refused."""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path

import click
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mhtrack.cli.main import cli

FUZZ = settings(derandomize=True, deadline=None, max_examples=150, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])

PLOTS = "scan,time,sensor,x,y\n1,1,0,10,20\n2,2,0,30,40\n"
TRUTH = "scan,time,target_id,x,y,vx,vy\n1,1,0,10,20,1,1\n2,2,0,30,40,1,1\n"


def _digest(paths: list[Path]) -> list[str]:
    return [hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "-" for p in paths]


def refused(args: list[str], *inputs: Path) -> str:
    """Run ``mhtrack ARGS``: exit 2, one line, no traceback, inputs unchanged."""
    before = _digest(list(inputs))
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 2, (r.exit_code, r.output, r.exception)
    assert not isinstance(r.exception, Exception) or isinstance(r.exception, SystemExit), \
        r.exception
    err = r.stderr if hasattr(r, "stderr") else r.output
    lines = [ln for ln in err.splitlines() if ln.startswith("Error:")]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert _digest(list(inputs)) == before
    return lines[0]


@pytest.fixture
def files(tmp_path: Path) -> Path:
    (tmp_path / "plots.csv").write_text(PLOTS)
    (tmp_path / "truth.csv").write_text(TRUTH)
    return tmp_path


def test_scan_beyond_2_53(files: Path) -> None:
    p = files / "big.csv"
    p.write_text(f"scan,time,sensor,x,y\n{2**53 + 1},1,0,1,1\n")
    line = refused(["track", str(p), "--out", str(files / "t.csv")], p)
    assert line == (f"Error: {p}, line 2, column 'scan': value 9007199254740993 is out of "
                    "range (expected an integer in [-2^53, 2^53])")


@pytest.mark.parametrize("tid", ["1e20", str(10**20)])
def test_track_id_1e20(files: Path, tid: str) -> None:
    tracks = files / "tracks.csv"
    tracks.write_text(f"scan,time,track_id,x,y,vx,vy,plot\n1,1,{tid},1,1,0,0,\n")
    line = refused(["evaluate", str(tracks), str(files / "truth.csv")], tracks)
    assert line.startswith(f"Error: {tracks}, line 2, column 'track_id': value ")
    assert ("out of range (expected an integer in [-2^53, 2^53])" in line
            or "is not an integer" in line)


@pytest.mark.parametrize(("args", "message"), [
    (["simulate", "crossing", "--seed", "1e20"],
     "Invalid value for '--seed': '1e20' is not an integer in [0, 2^63 - 1]"),
    (["simulate", "crossing", "--seed", str(2**64)],
     f"Invalid value for '--seed': '{2**64}' is not an integer in [0, 2^63 - 1]"),
    (["simulate", "crossing", "--clutter-rate", "1e308"],
     "Invalid value for '--clutter-rate': '1e308' is not a finite number in [0, 1e7]"),
    (["simulate", "crossing", "--clutter-rate", "nan"],
     "Invalid value for '--clutter-rate': 'nan' is not a finite number in [0, 1e7]"),
    (["evaluate", "T", "T", "--cutoff", "1e308"],
     "Invalid value for '--cutoff': '1e308' is not a finite number in (0, 1e7]"),
    (["evaluate", "T", "T", "--order", "inf"],
     "Invalid value for '--order': 'inf' is not a finite number in [1, 20]"),
])
def test_numbers_out_of_range_name_the_option_and_range(files: Path, args: list[str],
                                                        message: str) -> None:
    args = [str(files / "truth.csv") if a == "T" else a for a in args]
    args += ["--out", str(files / "o")] if args[0] == "simulate" else []
    assert refused(args) == f"Error: {message}"


def test_cutoff_at_its_bound_gives_finite_json(files: Path) -> None:
    """The largest cut-off allowed gives numbers, not null (1e308 gave null: c^p = inf):
    tracks 1e8 m away from the truth are at the cut-off."""
    tracks = files / "far.csv"
    tracks.write_text("scan,time,track_id,x,y,vx,vy,plot\n1,1,0,1e8,20,1,1,\n"
                      "2,2,0,1e8,40,1,1,\n")
    r = CliRunner().invoke(cli, ["evaluate", str(tracks), str(files / "truth.csv"),
                                 "--cutoff", "1e7", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d["ospa"] == [1e7, 1e7]
    assert all(math.isfinite(v) for v in d["gospa"])


@pytest.mark.parametrize(("text", "where"), [
    ("T = " + "[" * 3000 + "]" * 3000, "nested more than 64 levels deep"),
    ("T = {a = 1}", "T: expected a number, got table {'a': 1}"),
], ids=["deep", "table-for-number"])
def test_scenario_toml(files: Path, text: str, where: str) -> None:
    import tomli_w

    from mhtrack.scenario import preset

    d = preset("crossing").to_dict()
    del d["T"]
    p = files / "s.toml"
    p.write_text(text + "\n" + tomli_w.dumps(d))
    line = refused(["simulate", str(p), "--out", str(files / "o")], p)
    assert line.startswith(f"Error: {p}") and where in line


def test_scenario_rate_1e308(files: Path) -> None:
    from mhtrack.io import write_scenario_toml
    from mhtrack.scenario import preset

    d = preset("crossing").to_dict()
    d["clutter"] = {"kind": "uniform", "rate": 1e308}
    p = files / "s.toml"
    write_scenario_toml(d, p)
    line = refused(["simulate", str(p), "--out", str(files / "o")], p)
    assert line.startswith(f"Error: {p}: clutter.rate: ")


def test_montecarlo_json_holding_a_list(files: Path) -> None:
    out = files / "mc"
    out.mkdir()
    spec = out / "montecarlo.json"
    spec.write_text("[1, 2]\n")
    line = refused(["montecarlo", "crossing", "--runs", "1", "--trackers", "mht",
                    "--out", str(out)], spec)
    assert line == (f"Error: {spec}: expected a JSON object (a Monte-Carlo study), got "
                    "array")


def test_long_cell_and_wide_header(files: Path) -> None:
    cell = files / "cell.csv"
    cell.write_text("scan,time,sensor,x,y\n1,1,0,1,1\n1,1,0," + "9" * 5_000_000 + ",1\n")
    line = refused(["track", str(cell), "--out", str(files / "t.csv")], cell)
    assert line == (f"Error: {cell}, line 3, column 'x': cell of 5000000 characters, on a "
                    "line of 5000008 bytes: longer than the 1048576 bytes a line may hold "
                    "(expected a number)")
    wide = files / "wide.csv"
    wide.write_text(",".join(f"c{i}" for i in range(200_000)) + "\n1\n")
    line = refused(["track", str(wide), "--out", str(files / "t.csv")], wide)
    assert line.startswith(f"Error: {wide}, line 1: header has more than ")
    assert line.endswith("columns, more than the 10000 allowed")


def test_plot_index_out_of_range_in_plot(files: Path) -> None:
    d = files / "run"
    d.mkdir()
    (d / "plots.csv").write_text(PLOTS)
    tracks = d / "tracks.csv"
    tracks.write_text("scan,time,track_id,x,y,vx,vy,plot\n1,1,0,1,1,0,0,0\n2,2,0,1,1,0,0,7\n")
    line = refused(["plot", str(d)], tracks, d / "plots.csv")
    assert line == (f"Error: {tracks}, line 3, column 'plot': plot 7 is not a row of the "
                    "plots file (2 plots)")


@pytest.mark.parametrize("kind", ["fifo", "dir", "device"])
def test_inputs_that_are_not_regular_files_are_refused(files: Path, kind: str) -> None:
    if kind == "fifo":
        p = files / "p.csv"
        os.mkfifo(p)
        what = "is a FIFO (named pipe), not a regular file"
    elif kind == "dir":
        p = files / "d.csv"
        p.mkdir()
        what = "is a directory"
    else:
        p = files / "null.csv"
        p.symlink_to("/dev/null")
        what = "is a device, not a regular file"
    line = refused(["track", str(p), "--out", str(files / "t.csv")])
    assert line.startswith(f"Error: {p}: {what}") or (
        kind == "dir" and line.endswith(f"File '{p}' is a directory."))


def _number_options() -> list[tuple[str, click.Parameter]]:
    out = []
    for name, cmd in sorted(cli.commands.items()):
        subs = getattr(cmd, "commands", None) or {"": cmd}
        for sub_name, sub in sorted(subs.items()):
            for p in sub.params:
                if isinstance(p.type, click.IntRange | click.FloatRange):
                    out.append((f"{name} {sub_name} {p.name}", p))
    return out


NUMBER_OPTIONS = _number_options()
texts = st.one_of(
    st.text(max_size=12), st.integers().map(str), st.floats().map(repr),
    st.sampled_from(["1e20", "1e308", "-1e308", "nan", "inf", "-0", "0x10", str(2**53 + 1),
                     str(2**63), "1_000", " 5 ", "", "١"]))


def test_every_number_option_is_bounded() -> None:
    assert len(NUMBER_OPTIONS) > 20
    for _, p in NUMBER_OPTIONS:
        t = p.type
        assert t.min is not None and t.max is not None, p.name
        assert abs(t.min) <= 2**63 and abs(t.max) <= 2**63, p.name


@FUZZ
@given(pick=st.integers(0, 10**6), text=texts)
def test_any_text_is_a_number_in_range_or_refused(pick: int, text: str) -> None:
    _, p = NUMBER_OPTIONS[pick % len(NUMBER_OPTIONS)]
    t = p.type
    try:
        v = t.convert(text, p, None)
    except click.BadParameter as e:
        assert "\n" not in e.format_message()
        return
    assert math.isfinite(v)
    assert (t.min < v if t.min_open else t.min <= v) and (v < t.max if t.max_open else
                                                          v <= t.max)


def test_p2_job_record_of_the_wrong_shape_names_the_file_and_field(tmp_path: Path) -> None:
    from mhtrack.errors import InputError
    from mhtrack.experiments.jobs import JobStore
    from mhtrack.experiments.p2.jobs import STORE_FORMAT, check_record, make_jobs

    job = next(j for j in make_jobs(1, 0, [10.0, 20.0], [20.0], [50.0])
               if j.params["kind"] == "grid")
    store = JobStore(tmp_path, STORE_FORMAT, check=check_record)
    good = {"found": [1, 2], "false": [0, 0], "tracks": [1, 2], "n_targets": 3,
            "n_windows": 1, "non_monotone_windows": 0, "seconds": 0.5}
    store.save(job, good)
    assert store.load(job) == good
    store.save(job, {**good, "found": [1]})
    with pytest.raises(InputError) as info:
        store.load(job)
    assert str(info.value) == (f"{store.path(job.key)}, key 'result.found': expected a list "
                               "of 2 counts (one per θ), got a list of 1")
    p = store.path(job.key)
    d = json.loads(p.read_text())
    d["result"] = [1]
    p.write_text(json.dumps(d))
    with pytest.raises(InputError, match=r"key 'result': expected an object, got list"):
        store.load(job)


def test_run_file_with_bad_content_is_named(tmp_path: Path) -> None:
    """A Monte-Carlo run file that holds its job's hash but not a run's record (one row,
    the per-scan lists as long as ``scans``) is named, with the field."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = tmp_path / "mc"
    args = ["montecarlo", "crossing", "--runs", "1", "--scans", "3", "--trackers",
            "mht-agmm", "--workers", "1", "--out", str(out)]
    assert CliRunner().invoke(cli, args).exit_code == 0
    run = out / "runs" / "mht-agmm" / "run-0.parquet"
    t = pq.read_table(run)
    i = t.schema.get_field_index("scans")
    bad = t.set_column(i, "scans", pa.array([[1]], pa.list_(pa.int64())))
    pq.write_table(bad.replace_schema_metadata(t.schema.metadata), run)
    line = refused(args, run)
    assert line == (f"Error: {run}, key 'result.ospa': expected a list of 1 values (one per "
                    "scan), got a list of 3")
    pq.write_table(pa.concat_tables([t, t]).replace_schema_metadata(t.schema.metadata), run)
    assert refused(args, run) == (f"Error: {run}: a job record holds one row, this one 2")
