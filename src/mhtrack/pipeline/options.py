"""What a user may set for a tracking run (:class:`TrackOptions`, ``None``: the library's
default), and the one place each default is chosen (:func:`choose`) from what the source
knows: its scenario, its sensors, its plots' extent (``docs/architecture.md``, *Where
each default is chosen*)."""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from mhtrack.build import (
    DEFAULT_CLUTTER_DENSITY,
    P1_BIRTHS_PER_SCAN,
    TRACKER_FUSERS,
    PlotsArea,
    RadarRule,
    capped_pd,
    config_with,
    default_config,
    default_fusion,
    known_kappa_mismatch,
    make_tracker,
    plots_area,
    radar_rule,
    takes_clutter_density,
)
from mhtrack.mht import MHTConfig
from mhtrack.names import (
    DEFAULT_CLUTTER_FRAME,
    DEFAULT_OUTPUT,
    DEFAULT_TRACKER,
    RADAR_OUTPUT,
    TRACKER_FUSIONS,
)
from mhtrack.sinks.base import check_output

if TYPE_CHECKING:
    from mhtrack.mht import MHTTracker
    from mhtrack.models.geodesy import LocalFrame
    from mhtrack.sources.base import Source, Survey

log = logging.getLogger("mhtrack")


@dataclass(frozen=True)
class TrackOptions:
    """A tracking run's settings; every ``None`` is chosen by :func:`choose`."""

    #: Tracker name (:data:`mhtrack.names.TRACKERS`).
    tracker: str = DEFAULT_TRACKER
    #: :class:`~mhtrack.mht.MHTConfig` fields set by the user (``None``: the default
    #: configuration's, :func:`~mhtrack.build.default_config`).
    p_detection: float | None = None
    sigma_w: float | None = None
    sigma_v: float | None = None
    imm_sigma_v: float | None = None
    new_target_density: float | None = None
    n_scan: int | None = None
    startup_density: bool | None = None
    defer_tentative: bool | None = None
    #: The known κ of ``--tracker mht`` (default :data:`~mhtrack.build.DEFAULT_CLUTTER_DENSITY`).
    clutter_density: float | None = None
    #: Birth process (:data:`mhtrack.names.BIRTHS`) and θ of the modified initiators.
    birth: str | None = None
    birth_theta_deg: float | None = None
    #: Plot fusion (:data:`mhtrack.names.TRACKER_FUSIONS`; default
    #: :func:`~mhtrack.build.default_fusion`, none for timed plots).
    fusion: str | None = None
    #: Clutter frame of timed plots (:data:`mhtrack.names.CLUTTER_FRAMES`).
    clutter_frame: str = DEFAULT_CLUTTER_FRAME
    #: Output mode (:data:`mhtrack.names.OUTPUTS`); ``None``: chosen by :func:`choose`.
    output: str | None = None
    #: The sensors' ``P_D`` the user set for a simulation (``run --pd``): the tracker
    #: assumes it (:func:`~mhtrack.build.capped_pd`) unless ``p_detection`` is given.
    sensor_pd: float | None = None
    #: Keywords of the tracker's clutter estimator (:func:`~mhtrack.build.make_tracker`).
    clutter_params: dict[str, Any] | None = None
    #: Estimate and remove the radars' registration biases online
    #: (:mod:`mhtrack.pipeline.registration`); the reference radar (None: ADS-B if any,
    #: else the lowest polar id) and the biases to start from (``{id: RadarBias}``).
    estimate_bias: bool = False
    bias_reference: int | None = None
    bias_prior: dict[int, Any] | None = None

    def config_changes(self) -> dict[str, Any]:
        """The configuration fields set (``sensor_pd`` as the tracker's ``P_D``)."""
        pd = self.p_detection
        if pd is None and self.sensor_pd is not None:
            pd = capped_pd(self.sensor_pd)
        fields = {"p_detection": pd, "sigma_w": self.sigma_w, "sigma_v": self.sigma_v,
                  "new_target_density": self.new_target_density, "n_scan": self.n_scan,
                  "imm_sigma_v": self.imm_sigma_v, "startup_density": self.startup_density,
                  "defer_tentative": self.defer_tentative}
        return {k: v for k, v in fields.items() if v is not None}


@dataclass(frozen=True)
class Choices:
    """What :func:`choose` decided for one source."""

    config: MHTConfig
    fusion: str
    tracker: MHTTracker
    #: The local frame of geodetic radars (``lat, lon`` columns of the tracks), or None.
    frame: LocalFrame | None
    #: The surveillance area taken from the plots (no scenario), or None.
    area: PlotsArea | None
    #: Where the new-target density came from, for :func:`birth_density_note`.
    area_text: str
    #: The defaults taken from rotating radars (timed plots without a scenario), or None.
    radars: RadarRule | None = None
    #: The output mode (:data:`mhtrack.names.OUTPUTS`).
    output: str = DEFAULT_OUTPUT


def choose(source: Source, options: TrackOptions, survey: Survey | None,
           config: MHTConfig | None = None, *, live: bool = False) -> Choices:
    """Every default of a run on ``source``, chosen once:

    * configuration: ``config`` if given, else :func:`~mhtrack.build.default_config` of
      the scenario's region; else, for timed plots of rotating radars, ``λv`` (and the
      known κ of ``mht``) from the radars (:func:`~mhtrack.build.radar_rule`); else of the
      plots' robust area (:func:`survey_area`), else P1's; then the options' fields;
    * fusion: none for timed plots (one sensor per frame), else
      :func:`~mhtrack.build.default_fusion` of the scenario's or the plots' sensors;
    * the tracker (:func:`~mhtrack.build.make_tracker`) with the source's sensors
      (radar coverage, per-radar clutter in ``clutter_frame``);
    * the output frame: the sensors' local frame when they have a geodetic reference;
    * the output mode: ``"online"`` for a ``live`` run (it reports what it tracked as it
      goes), else :data:`~mhtrack.names.RADAR_OUTPUT` (the history smoothed) for timed
      plots of rotating radars, else :data:`~mhtrack.names.DEFAULT_OUTPUT`.
    """
    scenario, area, radars = source.scenario, None, None
    if config is None and scenario is not None:
        config = default_config(scenario)
    elif config is None and source.timed and survey is not None:
        radars = radar_rule(source.sensors, survey.sensor, survey.time, survey.x, survey.y,
                            v_max=MHTConfig().v_max)
    if config is None and radars is not None:
        config = MHTConfig(new_target_density=radars.new_target_density)
    elif config is None:
        area = survey_area(source.name, survey)
        config = default_config(area=area.area) if area is not None else default_config()
    config = config_with(config, **options.config_changes())
    if options.clutter_density is not None and not takes_clutter_density(options.tracker):
        raise ValueError(f"--clutter-density sets the known clutter intensity of --tracker "
                         f"mht; --tracker {options.tracker} estimates it online")
    fusion = options.fusion
    if fusion is None:
        fusion = "none" if source.timed else default_fusion(_n_sensors(source, survey))
    if fusion not in TRACKER_FUSIONS:
        raise ValueError(f"unknown fusion {fusion!r} (expected {', '.join(TRACKER_FUSIONS)})")
    if source.timed and TRACKER_FUSERS[fusion] is not None:
        raise ValueError("plots with their own times are tracked frame by frame, one "
                         f"sensor per frame: use fusion 'none', not {fusion!r}")
    kappa = options.clutter_density
    if kappa is None and radars is not None and takes_clutter_density(options.tracker):
        kappa = radars.clutter_density
    tracker = make_tracker(options.tracker, config, clutter_density=kappa,
                           birth=options.birth, theta_deg=options.birth_theta_deg,
                           sensors=source.sensors, clutter_params=options.clutter_params,
                           clutter_frame=options.clutter_frame)
    sensors = source.sensors
    frame = sensors.frame() if sensors is not None and sensors.reference is not None else None
    text = ("the scenario's region" if scenario is not None
            else f"the plots' {area.width / 1e3:.3g} km × {area.height / 1e3:.3g} km "
            "bounding box" if area is not None else "P1's 8 km × 8 km region")
    output = options.output
    if output is None:
        output = ("online" if live else RADAR_OUTPUT if radars is not None
                  else DEFAULT_OUTPUT)
    return Choices(config, fusion, tracker, frame, area, text, radars, check_output(output))


def _n_sensors(source: Source, survey: Survey | None) -> int:
    if source.scenario is not None:
        return len(source.scenario.sensors)
    if survey is not None:
        return len(survey.sensors)
    return 0 if source.sensors is None else len(source.sensors.sensors)


def survey_area(name: str, survey: Survey | None) -> PlotsArea | None:
    """The surveillance area of plots with no scenario: the robust box of
    :func:`~mhtrack.build.plots_area` around the survey's plots (``None`` with fewer than
    two plots or no survey); warns about plots far outside it."""
    if survey is None or survey.x is None or survey.y is None or survey.n_plots <= 1:
        return None
    box = plots_area(survey.x, survey.y)
    if box.n_far:
        log.warning(
            "%s: %d of %d plots lie far outside the box holding the middle 99%% of the plots "
            "(x %.6g to %.6g m, y %.6g to %.6g m); the surveillance area (%.4g m²) is taken "
            "from that box — check those plots, or pass --scenario with the true region",
            name, box.n_far, survey.n_plots, box.x0, box.x1, box.y0, box.y1, box.area)
    return box


def warn_known_kappa(scenario: Any, options: TrackOptions) -> None:
    """Warn when a known-clutter tracker keeps P1's κ (no ``clutter_density`` given) on a
    scenario whose clutter is 10× denser or sparser
    (:func:`~mhtrack.build.known_kappa_mismatch`)."""
    if not takes_clutter_density(options.tracker) or options.clutter_density is not None:
        return
    mean = known_kappa_mismatch(scenario)
    if mean is not None:
        log.warning(
            "tracker mht assumes P1's clutter density %.3g per m²; this scenario's clutter "
            "averages %.3g per m² over its region: pass --clutter-density %.3g, or use "
            "mht-agmm, which estimates it", DEFAULT_CLUTTER_DENSITY, mean, mean)


def birth_density_note(density: float, where: str) -> str:
    """The line saying which new-target density a run used when none was given
    (:func:`~mhtrack.build.default_config`)."""
    return (f"new-target density λv = {density:.4g} per m² per scan: P1's "
            f"{P1_BIRTHS_PER_SCAN:g} new targets per scan over {where} (--birth-density "
            "sets it)")
