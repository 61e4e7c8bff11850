"""``reproduce p1``: the P1 §3 study, Table 3 beside the paper, report and Figs. 2–6."""

import json
import math
import re
import struct

import pytest
from click.testing import CliRunner

from mhtrack.cli.reproduce_commands import COMMANDS, reproduce
from mhtrack.experiments.p1 import constants as rp
from mhtrack.experiments.p1 import reproduce_p1
from mhtrack.experiments.p1 import study as p1_study
from mhtrack.reports.p1 import write_p1_report
from mhtrack.reports.p1_text import fmt
from mhtrack.scenario import preset

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
FILES = ("table3.md", "table3.json", "report.md", *rp.FIGURES.values())


def run_p1(out):
    study = reproduce_p1(out, runs=2, seed=3, scenario=preset("crossing", scans=15),
                         workers=1)
    return study, write_p1_report(study)


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    return run_p1(tmp_path_factory.mktemp("p1"))


@pytest.fixture(scope="module")
def repro(both):
    return both[0]


@pytest.fixture(scope="module")
def report(both):
    return both[1]


def png_size(path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC, path
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_files_exist(repro):
    for name in FILES:
        assert (repro.out_dir / name).is_file(), name
    mc = repro.out_dir / "montecarlo"
    assert (mc / "montecarlo.json").is_file()
    assert (mc / "summary.md").is_file()
    for t in rp.P1_TRACKERS:
        for i in range(2):
            assert (mc / "runs" / t / f"run-{i}.parquet").is_file()
    assert repro.result.ok


def test_figures_are_png(repro, report):
    for key, name in rp.FIGURES.items():
        w, h = png_size(repro.out_dir / name)
        assert w >= 400 and h >= 300, (name, w, h)
        assert report.figures[key] == repro.out_dir / name
    w, h = png_size(repro.out_dir / rp.FIGURES["fig4"])
    assert w > 2 * h  # three panels side by side


def test_table_holds_paper_and_ours(repro):
    md = (repro.out_dir / "table3.md").read_text()
    s = repro.result.summary()
    for t in rp.P1_TRACKERS:
        label = rp.TRACKER_LABELS[t]
        paper_row = next(line for line in md.splitlines()
                         if line.startswith(f"| {label} | P1 (as printed) |"))
        ours_row = next(line for line in md.splitlines()
                        if line.startswith(f"| {label} | ours, best settings (2 runs) |"))
        paper_cells = [c.strip() for c in paper_row.strip("|").split("|")][2:]
        ours_cells = [c.strip() for c in ours_row.strip("|").split("|")][2:]
        assert len(paper_cells) == len(ours_cells) == len(rp.TABLE3_METRICS)
        for m, pc, oc in zip(rp.TABLE3_METRICS, paper_cells, ours_cells, strict=True):
            if m.key in rp.PAPER_TABLE3[t]:
                assert pc == fmt(m.key, rp.PAPER_TABLE3[t][m.key])
            else:
                assert pc == "–"
            mean, std = s[t][m.key], s[t]["std"][m.key]
            assert oc == f"{fmt(m.key, mean)} ± {fmt(m.key, std)}", (t, m.key)
    assert "0.9703" in md and "64.44" in md  # P1's MHT-AGMM Rcc and Lavg


def test_numbers_equal_summary_means(repro):
    s = repro.result.summary()
    js = json.loads((repro.out_dir / "table3.json").read_text())
    for t in rp.P1_TRACKERS:
        for m in rp.TABLE3_METRICS:
            mean = s[t][m.key]
            assert repro.table[t][m.key]["mean"] == mean or (
                math.isnan(mean) and math.isnan(repro.table[t][m.key]["mean"]))
            stored = js["table"][t][m.key]["mean"]
            assert (stored is None and math.isnan(mean)) or stored == mean
            # the means are those of the run files
            vals = [r[m.key] for r in repro.result.records[t]]
            assert mean == pytest.approx(sum(vals) / len(vals), rel=1e-12)


def test_run0_recomputed_with_runner_seed(repro):
    for t in rp.P1_TRACKERS:
        rec = next(r for r in repro.result.records[t] if r["run"] == 0)
        assert rec["seed"] == repro.run0_seed
        got = repro.run0[t].summary()
        for k in ("rcc", "rfg", "l_avg", "ospa_mean", "n_tracks"):
            assert got[k] == pytest.approx(rec[k], nan_ok=True), (t, k)


def test_report(repro, report):
    text = report.report_path.read_text()
    for name in rp.FIGURES.values():
        assert f"]({name})" in text
    assert "## Settings" in text and "λ = 40" in text and "κ = 1e-09" in text
    assert "Where our numbers differ" in text
    assert "Known reasons" in text
    # generated comparison: one verdict line per tracker and P1 metric
    for t in rp.P1_TRACKERS:
        assert f"**{rp.TRACKER_LABELS[t]}**" in text
    verdicts = re.findall(r"^\* (Rcc|Rmc|Rfg|Tavg \(s\)|Lmin \(s\)|Lavg \(s\)|Lmax \(s\)): ours ",
                          text, flags=re.M)
    assert len(verdicts) == 7 * 3
    rcc = repro.table["mht-agmm"]["rcc"]["mean"]
    assert f"Rcc: ours {fmt('rcc', rcc)}" in text


def test_resume_computes_nothing(repro, report):
    again, again_report = run_p1(repro.out_dir)
    assert again.result.computed == 0 and again.result.skipped == 6
    assert again_report.table_md == report.table_md  # Tavg too is read back from the files


def test_paired_comparisons_in_json_match_their_intervals(repro):
    js = json.loads((repro.out_dir / "table3.json").read_text())
    assert js["tracker_settings"] == "best"
    pairs = js["paired"]
    # three tracker pairs × nine metrics (P1's six without Tavg, OSPA, OSPA(2), HOTA)
    assert len(pairs) == 3 * 9
    assert {(p["a"], p["b"]) for p in pairs} == {
        ("MHT-AGMM", "MHT-GMM"), ("MHT-AGMM", "MHT"), ("MHT-GMM", "MHT")}
    for p in pairs:
        lo, hi = p["ci_low"], p["ci_high"]
        if lo is None or not (lo > 0 or hi < 0):
            assert p["verdict"] == "no detectable difference", p
        else:
            assert p["verdict"] == ("better" if (lo > 0) == p["higher_better"] else "worse")
        # the per-run values of the run files give the same mean difference
        ta = next(t for t, lab in rp.TRACKER_LABELS.items() if lab == p["a"])
        tb = next(t for t, lab in rp.TRACKER_LABELS.items() if lab == p["b"])
        d = [ra[p["metric"]] - rb[p["metric"]] for ra, rb in
             zip(repro.result.records[ta], repro.result.records[tb], strict=True)]
        assert p["mean_diff"] == pytest.approx(sum(d) / len(d), abs=1e-12)


def test_report_has_no_unsupported_claim(repro, report):
    text = report.report_path.read_text()
    assert "best on" not in text and "best (or tied best)" not in text
    assert "## Paired comparisons" in text
    for c in repro.paired:
        assert c.sentence in text


def test_paper_settings_side_by_side(tmp_path):
    repro, _ = run_p1(tmp_path)  # its own directory: the module's stays best-only
    paper = reproduce_p1(repro.out_dir, runs=2, seed=3, scenario=preset("crossing", scans=15),
                         workers=1, settings="paper")
    rep = write_p1_report(paper)
    assert paper.result.out_dir == repro.out_dir / "montecarlo-paper"
    assert paper.result.spec.config == {"imm_sigma_v": 0.0}
    assert paper.result.spec.run_kwargs["output"] == "online"
    assert rep.table_path.name == "table3-paper.md"
    md = rep.table_path.read_text()
    for t in rp.P1_TRACKERS:
        label = rp.TRACKER_LABELS[t]
        for src in ("P1 (as printed)", "ours, P1's settings (2 runs)",
                    "ours, best settings (2 runs)"):
            assert f"| {label} | {src} |" in md
    # each tracker also against itself under the best settings
    cross = [c for c in paper.paired if "settings)" in c.a]
    assert len(cross) == 3 * 9
    js = json.loads((repro.out_dir / "table3-paper.json").read_text())
    assert set(js["other_settings"]) == {"best"}
    assert (repro.out_dir / "report-paper.md").is_file()
    # the best study, rerun (nothing to compute), now shows the paper rows too
    best = reproduce_p1(repro.out_dir, runs=2, seed=3, scenario=preset("crossing", scans=15),
                        workers=1)
    assert best.result.computed == 0
    md = write_p1_report(best).table_md
    assert md == (repro.out_dir / "table3.md").read_text()
    assert "| MHT-AGMM | ours, P1's settings (2 runs) |" in md


def test_cli_help():
    assert [reproduce] == COMMANDS
    from mhtrack.cli.main import cli  # every command's options (-v, -q, --progress)

    r = CliRunner().invoke(cli, ["reproduce", "p1", "--help"])
    assert r.exit_code == 0
    for opt in ("--runs", "--out", "--seed", "--workers", "--dask-scheduler", "--progress",
                "--quiet", "--tracker-settings"):
        assert opt in r.output


def test_cli_runs(tmp_path, monkeypatch):
    monkeypatch.setattr(p1_study, "p1_scenario", lambda: preset("crossing", scans=8))
    r = CliRunner().invoke(reproduce, ["p1", "--runs", "1", "--workers", "1", "--out",
                                       str(tmp_path), "--no-progress"])
    assert r.exit_code == 0, r.output
    assert "| MHT-AGMM | P1 (as printed) |" in r.stdout
    assert "| MHT-AGMM | ours, best settings (1 run) |" in r.stdout
    assert str(tmp_path / "report.md") in r.stdout
    for name in FILES:
        assert (tmp_path / name).is_file()


def test_cli_rejects_both_executors(tmp_path):
    r = CliRunner().invoke(reproduce, ["p1", "--workers", "1", "--dask-scheduler",
                                       "tcp://x:1", "--out", str(tmp_path)])
    assert r.exit_code != 0 and "not both" in r.output


def test_caps_reported_per_run(repro, report):
    # Every run's caps are in table3.json and the report says, per tracker, in how many
    # runs and at how many scans per run they acted — read back from the stored runs.
    js = json.loads((repro.out_dir / "table3.json").read_text())
    md = report.report_path.read_text()
    assert "## Hard caps, per run" in md
    for t, recs in repro.result.records.items():
        rows = js["caps_per_run"][t]
        assert [r["run"] for r in rows] == [r["run"] for r in recs]
        for row, rec in zip(rows, recs, strict=True):
            stored = json.loads(rec["caps"] or "{}")
            assert row["scans"] == stored.get("scans", 0)
            assert {k: v for k, v in row.items() if k not in ("run", "scans")} == {
                k: v for k, v in stored.items() if k != "scans"}
        n_hit = sum(1 for r in rows if r["scans"] > 0)
        label = {"mht": "MHT", "mht-gmm": "MHT-GMM", "mht-agmm": "MHT-AGMM"}[t]
        if n_hit:
            assert f"* {label}: caps acted in {n_hit} of {len(rows)} runs" in md
        else:
            assert f"* {label}: no cap acted in any of its {len(rows)} runs." in md


def _timeless_table(path):
    """table3.json without the timing column (Tavg) — the only thing allowed to differ."""
    d = json.loads(path.read_text())
    for row in d["table"].values():
        row.pop("t_avg", None)
    d["paired"] = [c for c in d["paired"] if c["metric"] != "t_avg"]
    return d


def test_two_workers_and_dask_give_the_same_table(repro, report, tmp_path):
    """Same command, same Table 3 with any executor (issue 17 item 4): local workers 2 and
    a Dask cluster against the in-process study of the fixture."""
    ref = _timeless_table(repro.out_dir / "table3.json")
    for name, kw in (("w2", {"workers": 2}), ("dask", None)):
        if kw is None:
            distributed = pytest.importorskip("distributed")
            with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                          dashboard_address=None) as cluster:
                st = reproduce_p1(tmp_path / name, runs=2, seed=3,
                                  scenario=preset("crossing", scans=15), executor="dask",
                                  scheduler=cluster.scheduler_address)
        else:
            st = reproduce_p1(tmp_path / name, runs=2, seed=3,
                              scenario=preset("crossing", scans=15), **kw)
        assert st.result.computed == 6
        write_p1_report(st)
        assert _timeless_table(tmp_path / name / "table3.json") == ref, name
