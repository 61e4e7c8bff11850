"""``live`` and ``replay``: track ASTERIX from the network, and play a recording onto it
(``docs/live.md``)."""

from __future__ import annotations

import math
import threading
from pathlib import Path
from typing import Any

import click

from mhtrack.cli.asterix_commands import needs_libasterix
from mhtrack.cli.clutter_options import clutter_estimator_options, clutter_params
from mhtrack.cli.common import clutter_frame_option
from mhtrack.cli.terminal import say
from mhtrack.cli.track_commands import (
    bias_fields,
    bias_options,
    birth_options,
    report_biases,
    track_options,
    tracker_options,
    young_track_fields,
    young_track_options,
)
from mhtrack.names import RELEASES


class Speed(click.ParamType):
    """A replay speed: a number above 0, or ``max`` (infinity: no waiting)."""

    name = "SPEED|max"

    def convert(self, value: object, param: click.Parameter | None,
                ctx: click.Context | None) -> float:
        if value == "max":
            return math.inf
        try:
            v = float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            v = math.nan
        if not 0 < v < math.inf:
            self.fail(f"{value!r} is not a number above 0 or 'max'", param, ctx)
        return v


class DelayArg(click.ParamType):
    """``P:SECONDS``: a chance in [0, 1] and a delay in seconds ≥ 0."""

    name = "P:SECONDS"

    def convert(self, value: object, param: click.Parameter | None,
                ctx: click.Context | None) -> tuple[float, float]:
        if isinstance(value, tuple):
            return value  # type: ignore[return-value]
        try:
            p, s = (float(x) for x in str(value).split(":"))
        except ValueError:
            p = s = math.nan
        if not (0 <= p <= 1 and 0 <= s < math.inf):
            self.fail(f"{value!r} is not P:SECONDS (a chance in [0, 1], seconds >= 0)",
                      param, ctx)
        return p, s


@click.command()
@click.argument("recording", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--to", "to", required=True, multiple=True, help="Destination "
              "udp://HOST:PORT (IPv6: udp://[ADDR]:PORT; a multicast group is sent to with "
              "TTL 1); repeat for redundant LANs: every datagram goes to each.")
@click.option("--speed", type=Speed(), default=None,
              help="Time scale: 1 real time, 10 ten times faster, max as fast as the socket "
              "takes them [1].")
@click.option("--loop", is_flag=True, help="Play the recording again and again until "
              "Ctrl-C, each pass's times of day moved on by the recording's span (whole "
              "seconds; wrapping at midnight): one longer feed.")
@click.option("--loops", type=click.IntRange(min=1), default=None,
              help="As --loop, this many passes.")
@click.option("--drop", type=click.FloatRange(0, 1), default=None,
              help="Damage (tests): each copy of a datagram is not sent with this chance "
              "[0].")
@click.option("--delay", type=DelayArg(), default=None,
              help="Damage (tests): each copy is sent SECONDS of recording time late with "
              "chance P (the delay scaled by --speed as the spacing is).")
@click.option("--seed", type=click.IntRange(min=0), default=None,
              help="Seed of --drop and --delay's draws: the same seed damages the same "
              "copies at any speed [0].")
@needs_libasterix
def replay(recording: Path, to: tuple[str, ...], speed: float | None, loop: bool,
           loops: int | None, drop: float | None, delay: tuple[float, float] | None,
           seed: int | None) -> None:
    """Send RECORDING's ASTERIX datagrams over UDP with their original spacing."""
    from mhtrack.sources.damage import Damage
    from mhtrack.sources.replay import replay as play
    from mhtrack.sources.udp import stop_on_signals

    p, s = delay or (Damage.delay, Damage.delay_s)
    drop = Damage.drop if drop is None else drop
    if drop + p > 1:
        raise click.BadParameter(f"--drop {drop} and --delay's chance {p} add up to "
                                 "more than 1", param_hint="--drop/--delay")
    damage = Damage(drop, p, s, Damage.seed if seed is None else seed)
    if loop and loops is not None:
        raise click.UsageError("--loop (endless) or --loops N, not both")
    with stop_on_signals(threading.Event()) as stop:
        stats = play(recording, to, loops=None if loop else (loops or 1), stop=stop,
                     damage=damage,
                     **({} if speed is None else {"speed": speed}))
    hurt = (f"; {stats.dropped} copies dropped, {stats.delayed} delayed"
            if drop or p else "")
    if stats.unmoved:
        hurt += f"; {stats.unmoved} blocks sent with their old times"
    say(f"sent {stats.datagrams} datagrams ({stats.bytes} bytes, {stats.passes} "
        f"passes) to {', '.join(to)}{hurt}")


@click.command()
@click.option("--listen", "listen", multiple=True, help="udp://HOST:PORT to listen on "
              "(a multicast group joins it; repeat for several LANs).")
@click.option("--stdin", "stdin", type=click.Choice(["raw", "len32"]), default=None,
              help="Read datagrams from stdin instead: raw ASTERIX data blocks back to back, "
              "or each datagram after its length (4 octets, big-endian).")
@click.option("--sensors", "sensors_file", required=True, type=click.Path(
              exists=True, dir_okay=False, path_type=Path),
              help="Sensors file: every radar's site and errors (its rotation period, if not "
              "taken from its CAT034 marks in the first rotations).")
@click.option("--day-from", type=click.Choice(["receive", "stream"]), default=None,
              help="The day of each time of day: from the receive clock (live feeds), or "
              "from the stream alone (a replayed recording) [receive].")
@click.option("--out-udp", multiple=True, help="Send the system tracks as CAT062 to "
              "udp://HOST:PORT (repeatable).")
@click.option("--out", "out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the system tracks as a CAT062 recording (.ast or .pcap).")
@click.option("--part-frames", type=click.IntRange(min=1), default=None,
              help="With --out: a new file STEM.partNNNN.SUFFIX every N frames.")
@click.option("--json", "as_json", is_flag=True, help="Print each frame's tracks as JSON "
              "lines on stdout.")
@click.option("--period-out", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Send every track on this period (s of data time), extrapolated to "
              "each tick, instead of each sector's tracks on update.")
@click.option("--status-every", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Print a status line on stderr every N seconds.")
@click.option("--status-json", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Write the status as JSON to this file (atomically) with "
              "every status (every 10 s without --status-every) and at the end.")
@click.option("--prometheus", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the status as Prometheus text (format 0.0.4) to this file.")
@click.option("--metrics-http", default=None, metavar="HOST:PORT",
              help="Serve the Prometheus text at http://HOST:PORT/metrics (:PORT: on "
              "127.0.0.1).")
@click.option("--view", "view", default=None, metavar="HOST:PORT",
              help="Serve a live view — tracks, radars and status on a lat/lon grid, "
              "updated every second — at http://HOST:PORT/ (:PORT: on 127.0.0.1).")
@click.option("--checkpoint", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Save the tracker's state to this file (atomically) when the run ends "
              "and every --checkpoint-every minutes of data time.")
@click.option("--checkpoint-every", type=click.FloatRange(min=0, min_open=True),
              default=None, help="Minutes of data time between checkpoints.")
@click.option("--resume", is_flag=True, help="Start from --checkpoint when it exists: the "
              "same track ids go on.")
@click.option("--reorder-window", "reorder_window_s", type=click.FloatRange(min=0),
              default=None, help="Plots may be out of time order by at most this many "
              "seconds [2].")
@click.option("--release", type=click.Choice(RELEASES), default=None,
              help="A sector to the tracker in track's time order (time: the output equals "
              "track's) or as soon as its own plots are in (radar: lower latency, another "
              "output; docs/live.md, Release by radar) [time].")
@click.option("--sector-frames", is_flag=True, help="Cut a radar's frames at its own CAT034 "
              "sector crossings and close each when the next crossing comes (as track "
              "--sector-frames; docs/live.md, Frames at the radar's sectors).")
@click.option("--idle-close", "idle_close_s", type=click.FloatRange(min=0), default=None,
              help="Close the frames held after this many wall-clock seconds without a "
              "datagram (a feed gone quiet); 0: never [the re-order window plus the "
              "longest rotation period].")
@click.option("--preload/--no-preload", default=True, show_default=True,
              help="Load the tracker's one-time code (SciPy's solvers, the compiled IMM "
              "rows) at start, not in the frame that first needs it (docs/live.md, Soak).")
@tracker_options("--pd")
@clutter_frame_option
@birth_options
@young_track_options
@clutter_estimator_options
@bias_options
@needs_libasterix
def live(listen: tuple[str, ...], stdin: str | None, sensors_file: Path,
         day_from: str | None, out_udp: tuple[str, ...], out: Path | None,
         part_frames: int | None, as_json: bool, period_out: float | None,
         status_every: float | None, status_json: Path | None, prometheus: Path | None,
         metrics_http: str | None, view: str | None, checkpoint: Path | None,
         checkpoint_every: float | None, resume: bool, reorder_window_s: float | None,
         release: str | None, sector_frames: bool, idle_close_s: float | None,
         preload: bool, tracker: str,
         tracker_pd: float | None, meas_sigma: float | None, accel_sigma: float | None,
         imm_accel_sigma: float | None, clutter_density: float | None,
         birth_density: float | None, nscan: int | None, clutter_frame: str, birth: str,
         birth_theta: float | None, fusion: str | None, estimate_bias: bool = False,
         bias_reference: int | None = None, bias_init: Path | None = None,
         bias_out: Path | None = None, startup_density: bool = False,
         defer_tentative: bool = False, **estimator_opts: Any) -> None:
    """Track ASTERIX plots arriving over UDP (or stdin) until Ctrl-C or SIGTERM."""
    from mhtrack.io.sensors import read_sensors
    from mhtrack.pipeline.live import Live, LiveOptions
    from mhtrack.sources.udp import stop_on_signals

    options = track_options(tracker, tracker_pd, meas_sigma, accel_sigma, imm_accel_sigma,
                            clutter_density, birth_density, nscan, birth, birth_theta,
                            fusion, "online", clutter_frame=clutter_frame,
                            **bias_fields(estimate_bias, bias_reference, bias_init, bias_out),
                            **young_track_fields(startup_density, defer_tentative, birth),
                            clutter_params=clutter_params(tracker, **estimator_opts))
    settings = LiveOptions(listen=listen, stdin=stdin, out_udp=out_udp, out_file=out,
                           part_frames=part_frames, json=as_json,
                           period_out_s=period_out, status_every_s=status_every,
                           status_json=status_json, prometheus=prometheus,
                           metrics_http=metrics_http, view=view, checkpoint=checkpoint,
                           checkpoint_every_s=(None if checkpoint_every is None
                                               else 60.0 * checkpoint_every),
                           resume=resume, reorder_window_s=reorder_window_s,
                           idle_close_s=idle_close_s, preload=preload,
                           sectors=sector_frames,
                           **({} if day_from is None else {"day_from": day_from}),
                           **({} if release is None else {"release": release}))
    with stop_on_signals(threading.Event()) as stop:
        run = Live(read_sensors(sensors_file), options, settings, stop=stop,
                   emit=lambda line: click.echo(line, err=True))
        result = run.run()
    say(result.describe(), err=True)
    report_biases(run.pipeline.registration, bias_out, err=True)


COMMANDS = [live, replay]
