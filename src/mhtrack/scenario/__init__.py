"""Scenario simulation: targets, sensors and clutter → plots and truth.

* :class:`Scenario` (``spec``) — the frozen description of a run, with a validated
  dict/TOML form (:meth:`Scenario.to_dict`, :func:`from_dict`, :func:`load_scenario`;
  the dict form of its parts in ``dictform``, its bounds in ``limits``);
* :class:`Target`, :class:`RecordedTarget` (``targets``) — constant-velocity or recorded truth;
* :func:`simulate` (``simulate``) — plots and truth from a scenario and a seed; with
  rotating radars :func:`simulate_rotating` (``sweep``: plots timed by the beam, on the
  WGS-84 ellipsoid; ``trajectory``: continuous-time truth; ``radardict``: their TOML
  form; ``radarset``: :meth:`Scenario.sensor_set`);
* :func:`preset`, :data:`PRESETS` (``presets``) — the papers' scenarios (``docs/scenarios.md``) and
  the OpenSky scenario; :func:`apply_overrides` (``overrides``) — the CLI's common
  overrides (clutter kind and rate, P_D, number of scans, …) for any scenario;
* :func:`load_opensky`, :func:`aircraft_ids` (``opensky``), :func:`geodetic_to_enu`
  (``geodesy``) — the real ADS-B data in a local frame.

Scan ``k`` is at time ``t = k·T`` (rotating radars: plots at their own times, over
``[first·T, last·T]``). See ``docs/scenarios.md``.
"""

from mhtrack.scenario.dictform import CLUTTER_KINDS, SENSOR_KINDS, clutter_to_dict
from mhtrack.scenario.geodesy import geodetic_to_enu
from mhtrack.scenario.opensky import OpenSkyTruth, aircraft_ids, load_opensky
from mhtrack.scenario.overrides import OVERRIDES, apply_overrides, default_mixture
from mhtrack.scenario.presets import PRESET_OVERRIDES, PRESETS, preset
from mhtrack.scenario.simulate import Simulation, simulate, simulate_rotating, simulate_truth
from mhtrack.scenario.spec import Scenario, from_dict, load_scenario
from mhtrack.scenario.targets import AnyTarget, RecordedTarget, Target

__all__ = [
    "CLUTTER_KINDS",
    "OVERRIDES",
    "PRESETS",
    "PRESET_OVERRIDES",
    "SENSOR_KINDS",
    "AnyTarget",
    "OpenSkyTruth",
    "RecordedTarget",
    "Scenario",
    "Simulation",
    "Target",
    "aircraft_ids",
    "apply_overrides",
    "clutter_to_dict",
    "default_mixture",
    "from_dict",
    "geodetic_to_enu",
    "load_opensky",
    "load_scenario",
    "preset",
    "simulate",
    "simulate_rotating",
    "simulate_truth",
]
