"""``live --sector-frames`` stopped with a checkpoint and resumed (``docs/live.md``,
*Checkpoints and restart*): the figures that page quotes.

    python benchmarks/resume_sectors.py [DIR] [--seed 1] [--scans 6]
        [--cuts 0.3 0.45 0.55 0.7]

``DIR`` (a temporary folder if not given) gets ``mhtrack simulate opensky-radars``
(``--seed``, ``--scans``) and its plots exported as ``radar.ast`` (CAT048 plots, CAT034
north markers and a sector crossing every 45°). ``live --sector-frames --stdin raw``
runs on its datagrams once to the end, then, for each cut, on the first ``cut`` of them,
stopped (as by SIGTERM) with a checkpoint once the reader has them all, and resumed on
the rest — and cut again before the first CAT034 datagram at or after that cut (the
resumed run's first datagram a crossing, which closes a frame of plots held). Each run
twice: with the datagrams as the reader queues them (``queued``: a
chunk is passed on whenever the reader's queue is empty, which depends on the threads'
timing) and with each datagram passed on alone (``alone``:
:data:`~mhtrack.sources.base.CAUGHT_UP` after every one — a crossing is then a chunk of
its own). Printed per cut and mode: whether the rows are those of the run never stopped,
the plots and crossings held in the checkpoint, and the resumed run's latency
bookkeeping (:class:`~mhtrack.pipeline.health.Health`): frames timed (``count``), of
them from their closing crossing (``by_crossing``), frames ``restored`` (counted apart),
``untimed``, late crossings. Every wait is bounded by counts (no wall-clock limit).
"""

from __future__ import annotations

import argparse
import io
import json
import os
import tempfile
import threading
import time
from pathlib import Path

OPTIONS = {"output": "online", "new_target_density": 1e-10}


def recording(out: Path, seed: int, scans: int) -> Path:
    """``out`` holding the simulation and its plots exported as ``radar.ast``."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    if (out / "radar.ast").exists():
        return out
    for args in (["simulate", "opensky-radars", "--seed", str(seed), "--scans", str(scans),
                  "--out", str(out)],
                 ["export", str(out / "plots.csv"), "--sensors", str(out / "sensors.toml"),
                  "--out", str(out / "radar.ast")]):
        r = CliRunner().invoke(cli, args)
        if r.exit_code != 0:
            raise SystemExit(r.output)
    return out


def run(rec: Path, blocks: list[bytes], alone: bool, stop_after: int | None = None,
        **live_options: object) -> tuple[list[dict], object]:
    """``live --stdin raw --sector-frames --day-from stream --json`` on ``blocks``: its
    JSON rows and the :class:`~mhtrack.pipeline.live.Live`; stopped once ``stop_after``
    datagrams were received (``None``: to the end)."""
    from mhtrack.io.sensors import read_sensors
    from mhtrack.pipeline import TrackOptions
    from mhtrack.pipeline.live import Live, LiveOptions

    r, w = os.pipe()
    stop = threading.Event()
    out = io.StringIO()
    with os.fdopen(r, "rb", buffering=0) as rf:
        live = Live(read_sensors(rec / "sensors.toml"), TrackOptions(**OPTIONS),
                    LiveOptions(preload=False, stdin="raw", day_from="stream", json=True,
                                sectors=True, **live_options),
                    stdin=rf, stdout=out, stop=stop)
        if alone:  # the reader's queue looks empty after every datagram: CAUGHT_UP
            live.reader.waiting = lambda: False  # type: ignore[method-assign]

        def feed() -> None:
            os.write(w, b"".join(blocks))
            if stop_after is not None:
                while live.reader.stats.datagrams < stop_after and not stop.is_set():
                    time.sleep(0.005)  # bounded by the count: the pipe holds them all
                stop.set()
            os.close(w)

        feeder = threading.Thread(target=feed)
        feeder.start()
        try:
            live.run()
        finally:
            stop.set()
            feeder.join()
    return [json.loads(x) for x in out.getvalue().splitlines()], live


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", type=Path, nargs="?")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scans", type=int, default=6)
    ap.add_argument("--cuts", type=float, nargs="+", default=[0.3, 0.45, 0.55, 0.7])
    a = ap.parse_args()
    from mhtrack.sources.replay import recording_datagrams

    with tempfile.TemporaryDirectory() as tmp:
        rec = recording(a.dir or Path(tmp), a.seed, a.scans)
        blocks = [d if isinstance(d, bytes) else d[0]
                  for d in recording_datagrams(rec / "radar.ast")]
        print(f"opensky-radars seed {a.seed}, {a.scans} scans: {len(blocks)} datagrams")
        for alone in (False, True):
            mode = "alone" if alone else "queued"
            whole, _ = run(rec, blocks, alone)
            cuts = [int(c * len(blocks)) for c in a.cuts]
            cuts += [next((i for i in range(k, len(blocks)) if blocks[i][0] == 34), k)
                     for k in cuts]  # the first datagram after the cut: a crossing
            for k in cuts:
                cut = k / len(blocks)
                ck = Path(tmp) / f"state-{mode}-{k}.npz"
                first, one = run(rec, blocks[:k], alone, stop_after=k, checkpoint=ck)
                held = one.source.held or {}  # type: ignore[attr-defined]
                rows = [c for c in (held.get("framed"), held.get("held")) if c is not None]
                marks = sum(int(c["mark"].sum()) for c in rows)
                plots = sum(len(c["time"]) for c in rows) - marks
                second, two = run(rec, blocks[k:], alone, checkpoint=ck, resume=True)
                lat = two.health.snapshot()["latency_s"]  # type: ignore[attr-defined]
                late = two.source.stats.late_crossings  # type: ignore[attr-defined]
                cat = blocks[k][0] if k < len(blocks) else 0
                same = first + second == whole
                print(f"{mode:6s} cut {cut:.1%} ({k} datagrams, next CAT{cat:03d}): rows "
                      f"of the run never stopped {same}; held {plots} plots, {marks} "
                      f"crossings; resumed: timed {lat['count']} ({lat['by_crossing']} "
                      f"by crossing), restored {lat['restored']}, untimed "
                      f"{lat['untimed']}, late crossings {late}")


if __name__ == "__main__":
    main()
