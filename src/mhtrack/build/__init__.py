"""The tracker builder: every part by its name (:mod:`.parts`), and the MHT's defaults
fitted to the data (:mod:`.defaults`).

The CLI, the pipeline (:mod:`mhtrack.pipeline`), the experiments and users build
trackers here. Each name a user chooses a part by is listed once in
:mod:`mhtrack.names`; :mod:`.parts` holds the one table per kind of part from those
names to the classes, and nothing else branches on a part's name.

Layer: after ``mht`` and ``initiation``, before ``metrics`` and ``experiments``; it
imports neither of those, nor plotting or the CLI.
"""

from mhtrack.build.defaults import (
    AREA_QUANTILES,
    DEFAULT_CLUTTER_DENSITY,
    MAX_TRACKER_PD,
    P1_BIRTHS_PER_SCAN,
    PlotsArea,
    birth_density_for_area,
    capped_pd,
    config_with,
    default_config,
    default_fusion,
    known_kappa_mismatch,
    plots_area,
)
from mhtrack.build.parts import (
    BIRTH_FACTORIES,
    CLUTTER_ESTIMATOR_CLASSES,
    INITIATION_FUSER_CLASSES,
    TIMED_CONFIRM_MIN_PLOTS,
    TRACKER_ESTIMATORS,
    TRACKER_FUSERS,
    TRACKER_FUSION_CONSISTENCY,
    TRACKER_FUSION_WEIGHTING,
    birth_suffix,
    load_tracker,
    make_birth,
    make_clutter_estimator,
    make_tracker,
    radar_clutter,
    takes_clutter_density,
    tracker_fuser,
)
from mhtrack.build.radar_defaults import (
    RadarFigures,
    RadarRule,
    misses_to_delete,
    radar_rule,
)
from mhtrack.build.recipe import sensors_from_recipe, sensors_recipe
from mhtrack.initiation.factory import INITIATOR_CLASSES, make_initiator

__all__ = [
    "AREA_QUANTILES",
    "BIRTH_FACTORIES",
    "CLUTTER_ESTIMATOR_CLASSES",
    "DEFAULT_CLUTTER_DENSITY",
    "INITIATION_FUSER_CLASSES",
    "INITIATOR_CLASSES",
    "MAX_TRACKER_PD",
    "P1_BIRTHS_PER_SCAN",
    "TIMED_CONFIRM_MIN_PLOTS",
    "TRACKER_ESTIMATORS",
    "TRACKER_FUSERS",
    "TRACKER_FUSION_CONSISTENCY",
    "TRACKER_FUSION_WEIGHTING",
    "PlotsArea",
    "RadarFigures",
    "RadarRule",
    "birth_density_for_area",
    "birth_suffix",
    "capped_pd",
    "config_with",
    "default_config",
    "default_fusion",
    "known_kappa_mismatch",
    "load_tracker",
    "make_birth",
    "make_clutter_estimator",
    "make_initiator",
    "make_tracker",
    "misses_to_delete",
    "plots_area",
    "radar_clutter",
    "radar_rule",
    "sensors_from_recipe",
    "sensors_recipe",
    "takes_clutter_density",
    "tracker_fuser",
]
