"""What a live run reads and writes (:class:`LiveOptions`) and the defaults it derives
from them (``docs/live.md``): the wall-clock wait after which a quiet feed's frames are
closed, the metrics endpoint's address."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mhtrack.models.radars import SensorSet

DAY_FROM = ("receive", "stream")
#: Plots whose decoding-order number the source remembers (2 MB, at least the largest
#: frame: a burst of 10^5 plots in one sector fits).
KEEP_ROWS = 1 << 18
#: Status period (s) when a status file or endpoint is asked for without one.
DEFAULT_STATUS_EVERY_S = 10.0
#: Period output: a track is extrapolated at most this many of the longest radar
#: rotation periods past its own time (``LiveOptions.max_extrapolation_s``).
EXTRAPOLATION_PERIODS = 2.0


@dataclass(frozen=True)
class LiveOptions:
    """Where a live run reads and writes (``None``/empty: not used)."""

    #: ``udp://HOST:PORT`` endpoints to listen on (several LANs: merged).
    listen: tuple[str, ...] = ()
    #: Read stdin instead, with this framing (``raw`` or ``len32``).
    stdin: str | None = None
    #: How the day of a time of day is found (module docstring).
    day_from: str = "receive"
    #: ``udp://HOST:PORT`` destinations of the CAT062 system tracks.
    out_udp: tuple[str, ...] = ()
    #: CAT062 recording (``.ast`` or ``.pcap``), in parts of ``part_frames`` frames.
    out_file: Path | None = None
    part_frames: int | None = None
    #: JSON lines of the online rows on stdout.
    json: bool = False
    #: Send every output on this period of data time (s) instead of on update.
    period_out_s: float | None = None
    #: Period output: longest extrapolation of a track (s; ``None``: 2 rotations).
    max_extrapolation_s: float | None = None
    #: Seconds between status lines (``None``: none).
    status_every_s: float | None = None
    #: The status as a JSON file and as Prometheus text (file; HTTP ``HOST:PORT``).
    status_json: Path | None = None
    prometheus: Path | None = None
    metrics_http: str | None = None
    #: The live view's page and JSON at ``http://HOST:PORT/`` (``:PORT``: 127.0.0.1;
    #: :mod:`~mhtrack.pipeline.view`).
    view: str | None = None
    #: Tracker checkpoints: the file, every this many seconds of data time (``None``:
    #: only at the end); ``resume``: start from it when it exists.
    checkpoint: Path | None = None
    checkpoint_every_s: float | None = None
    resume: bool = False
    #: Load the tracker's one-time code at start (:mod:`~mhtrack.pipeline.preload`).
    preload: bool = True
    #: CAT062 data source (I062/010).
    sac: int | None = None
    sic: int | None = None
    reorder_window_s: float | None = None
    #: When a closed frame goes to the tracker (:mod:`~mhtrack.sources.framer`):
    #: ``"time"``, in ``track``'s order (the output equals ``track``'s online view);
    #: ``"radar"``, as soon as its own plots are in (lower latency, another output).
    release: str = "time"
    #: Frames cut and closed at each radar's own CAT034 sector crossings
    #: (``track --sector-frames``; :mod:`~mhtrack.sources.framer`).
    sectors: bool = False
    #: A quiet feed: after this many wall-clock seconds without a datagram the frames
    #: held are closed (``None``: the re-order window plus the longest rotation period;
    #: ``0``: never) — *A silent feed* in ``docs/live.md``.
    idle_close_s: float | None = None


def idle_wait(sensors: SensorSet, live: LiveOptions) -> float | None:
    """Wall-clock seconds without a datagram after which the frames held are closed
    (``None``: never): ``live.idle_close_s``, by default the re-order window plus the
    longest rotation period — at real time the data would have moved the frames on by
    then — or the default frame length for radars without one."""
    from mhtrack.frames import DEFAULT_FRAME_S
    from mhtrack.io.reorder import DEFAULT_REORDER_WINDOW_S

    if live.idle_close_s is not None:
        return float(live.idle_close_s) if live.idle_close_s > 0 else None
    window = DEFAULT_REORDER_WINDOW_S if live.reorder_window_s is None \
        else float(live.reorder_window_s)
    longest = longest_period(sensors)
    return window + (DEFAULT_FRAME_S if longest is None else longest)


def longest_period(sensors: SensorSet) -> float | None:
    """The longest period (s) among the sensors that have one — a radar's rotation, any
    other sensor's update period — or ``None``: what a quiet feed's wait
    (:func:`idle_wait`) and the periodic output's extrapolation limit are counted in."""
    return max((float(s.period) for s in sensors.sensors if s.period is not None),
               default=None)

