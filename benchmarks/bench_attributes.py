"""Plot attributes on ``opensky-radars`` (issue 29, acceptance): the same seeds with
secondary-radar attributes off and on, paired.

Per seed ``S``: ``mhtrack simulate opensky-radars --seed S --no-attributes|--attributes
--out D`` (the attributes come from their own random streams: the plots' positions, times
and origins are the same with and without), ``mhtrack track D/plots.csv --sensors D/sensors.toml
--out D/tracks-history.csv --output history`` (each confirmed track also at the scans
before its confirmation); the ``online`` view (what a display saw, ``--output online``)
is its rows with ``tentative`` 0 (:func:`online_rows`); and ``mhtrack evaluate
D/tracks-V.csv D/truth.csv --plots D/plots.csv --identity --json`` for both views. Figures: ids
per aircraft (``ids_per_aircraft``, :mod:`mhtrack.metrics.identity`), coverage, OSPA mean
(c = 500 m, p = 2), identity switches, horizontal RMS error and probability of update.

Each figure is compared attributes-on against -off by
:func:`mhtrack.metrics.paired.compare_paired` (mean paired difference with its 95 %
Student-t interval, sign and Wilcoxon tests). Single process (the machine is shared).
Run: ``PYTHONPATH=src python benchmarks/bench_attributes.py [seeds...]`` (default 1–10);
``--json FILE`` also writes every run's figures; ``--merge FILE`` starts from the runs
of such a file (seeds run in parts).
"""

from __future__ import annotations

import contextlib
import io
import json
import sys
import tempfile
from pathlib import Path

from mhtrack.cli.main import cli
from mhtrack.metrics.paired import compare_paired, verdict_sentence

#: (key in evaluate's JSON, label, higher is better, digits).
FIGURES = (("ids_per_aircraft", "ids / aircraft", False, 3),
           ("coverage", "coverage", True, 4),
           ("ospa_mean", "OSPA (m)", False, 1),
           ("id_switches", "id switches", False, 1),
           ("rms_horizontal", "RMS horizontal (m)", False, 1),
           ("p_update", "P(update)", True, 4))
VIEWS = ("online", "history")


def _cli(args: list[str]) -> str:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        cli.main(args, standalone_mode=False)
    return buf.getvalue()


def online_rows(history: Path, out: Path) -> None:
    """The rows of a history tracks file with ``tentative`` 0: what ``--output online``
    writes (the history is the online rows plus the confirmed tracks' tentative past),
    the lines copied as they are."""
    lines = history.read_text().splitlines(keepends=True)
    k = lines[0].rstrip("\r\n").split(",").index("tentative")
    out.write_text("".join([lines[0], *(ln for ln in lines[1:]
                                         if ln.rstrip("\r\n").split(",")[k] == "0")]))


def run_seed(seed: int, tmp: Path) -> dict[str, dict[str, dict[str, float]]]:
    """``{attributes: {view: figures}}`` of one seed."""
    out: dict[str, dict[str, dict[str, float]]] = {}
    for label, extra in (("off", ["--no-attributes"]), ("on", ["--attributes"])):
        d = tmp / f"{seed}-{label}"
        _cli(["simulate", "opensky-radars", "--seed", str(seed), "--out", str(d), "-q",
              *extra])
        _cli(["track", str(d / "plots.csv"), "--sensors", str(d / "sensors.toml"),
              "--out", str(d / "tracks-history.csv"), "--output", "history", "-q"])
        online_rows(d / "tracks-history.csv", d / "tracks-online.csv")
        out[label] = {}
        for view in VIEWS:
            tracks = d / f"tracks-{view}.csv"
            ev = json.loads(_cli(["evaluate", str(tracks), str(d / "truth.csv"), "--plots",
                                  str(d / "plots.csv"), "--identity", "--json", "-q"]))
            out[label][view] = {k: float(ev[k]) for k, *_ in FIGURES}
    print(f"seed {seed}: " + "; ".join(
        f"{label} {view}: " + ", ".join(f"{k} {out[label][view][k]:.4g}"
                                       for k, *_ in FIGURES)
        for label in out for view in VIEWS), flush=True)
    return out


def table(runs: dict[int, dict[str, dict[str, dict[str, float]]]]) -> str:
    """The paired table (markdown) and one verdict sentence per figure and view."""
    seeds = sorted(runs)
    lines = ["| view | figure | off (mean) | on (mean) | on − off | 95 % interval | "
             "verdict |", "|---|---|---|---|---|---|---|"]
    sentences = []
    for view in VIEWS:
        for key, label, higher, digits in FIGURES:
            a = [runs[s]["on"][view][key] for s in seeds]
            b = [runs[s]["off"][view][key] for s in seeds]
            c = compare_paired(a, b, metric=key, name_a="attributes on",
                               name_b="attributes off", higher_better=higher)
            lines.append(f"| {view} | {label} | {c.mean_b:.{digits}f} | {c.mean_a:.{digits}f}"
                         f" | {c.mean_diff:+.{digits + 1}f} | [{c.ci_low:+.{digits + 1}f}, "
                         f"{c.ci_high:+.{digits + 1}f}] | {c.verdict} |")
            sentences.append(verdict_sentence(c, digits + 1, label=f"{label} ({view})"))
    return "\n".join([*lines, "", *sentences])


def main(argv: list[str]) -> None:
    dump = None
    if "--json" in argv:
        i = argv.index("--json")
        dump = Path(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    merge = None
    if "--merge" in argv:  # runs of earlier seeds (a JSON this script wrote)
        i = argv.index("--merge")
        merge = Path(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    seeds = [int(s) for s in argv] or list(range(1, 11))
    runs = {} if merge is None else {int(k): v for k, v in
                                     json.loads(merge.read_text()).items()}
    for seed in seeds:
        with tempfile.TemporaryDirectory() as tmp:
            runs[seed] = run_seed(seed, Path(tmp))
        if dump is not None:
            dump.write_text(json.dumps(runs, indent=1))
    print(table(runs))


if __name__ == "__main__":
    main(sys.argv[1:])
