"""A short simulated ASTERIX recording for the live, checkpoint and replay tests."""

from __future__ import annotations

from pathlib import Path


def simulated_recording(out: Path, *, seed: int, scans: int, name: str = "radar.ast",
                        then: tuple[list[str], ...] = (),
                        simulate: tuple[str, ...] = ()) -> Path:
    """``out`` holding ``mhtrack simulate opensky-radars`` (``seed``, ``scans``) and its
    plots exported as ``name``; each of ``then`` (argument lists, ``{out}`` replaced by
    the folder) run after them; ``simulate``: more options of ``simulate`` (``--bias``).
    Any command failing fails the test."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    steps = [["simulate", "opensky-radars", "--seed", str(seed), "--scans", str(scans),
              "--out", str(out), *simulate],
             ["export", str(out / "plots.csv"), "--sensors", str(out / "sensors.toml"),
              "--out", str(out / name)],
             *([a.replace("{out}", str(out)) for a in args] for args in then)]
    for args in steps:
        r = CliRunner().invoke(cli, args)
        assert r.exit_code == 0, r.output
    return out
