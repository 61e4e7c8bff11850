"""Reference scenarios (``docs/scenarios.md``: P1 §3, P2 §3) and the OpenSky scenario, by name.

``preset(name, **overrides)`` builds one; :data:`PRESETS` lists the names. Values marked
*(ours)* are not in the papers: they are our documented choices (``docs/scenarios.md``).

* ``crossing`` (P1 §3, Table 1–2): region ``[−4000, 4000]²`` m, ``T = 1`` s, scans 1–90,
  ``P_D = 0.9``, one Cartesian sensor ``σw² = 10⁴ m²``; four targets (state given at their
  birth scan); clutter an equal-weight mixture of four Gaussians with the printed
  covariances read as m² (σ ≈ 28–32 m); ``λ = 40`` per scan *(ours)*.
* ``crossing-wide``: the same, covariances read as standard deviations (σ = 800, 1000 m).
* ``crossing-changing``: the crossing targets and sensor in a clutter field whose
  components appear, vanish, split, merge and drift, ``λ = 40`` per scan *(all ours;*
  :mod:`mhtrack.scenario.changing`).
* ``multiradar`` (P2 §2.2, §3): ten targets from the printed initial positions at 200 m/s,
  headings drawn once from ``default_rng(2013)`` *(ours)*; three polar radars ``σr = 20 m``,
  ``σθ = 0.3°`` 10 km from the centre of the targets' area at bearings 30°, 150°, 270°
  *(ours)*; region the square of area ``A₀ = 2·10⁸ m²`` centred on the targets' area;
  uniform clutter ``λ = 50`` per scan per radar; ``P_D = 1`` and 10 scans *(ours)*.
* ``opensky``: the real aircraft of the packaged data (:mod:`mhtrack.scenario.opensky`),
  ``T = 10`` s, scans 0–120; two polar radars near Heathrow and Manchester airports,
  ``σr = 50 m``, ``σθ = 0.15°``, ``P_D = 0.9``; Gaussian-mixture clutter of three
  components plus a 20 % uniform background, ``λ = 20`` per scan per radar *(all ours)*.
* ``opensky-radars``: the same aircraft (in the azimuthal-equidistant frame about
  ``opensky.REFERENCE``) seen by three rotating radars at real radar sites — Heathrow,
  Clee Hill, RAF Waddington — with periods 4, 10, 12 s, their own noises, ``P_D`` and
  clutter (uniform in range–azimuth and one patch each), 1200 s *(all ours;*
  :data:`OPENSKY_ROTATING_RADARS`, ``docs/scenarios.md``).
* ``radars-clutter``: two rotating radars and six aircraft, five minutes, for the
  clutter scenes of :mod:`mhtrack.scenario.scenes` (``--clutter-scene``) *(all ours)*.

Overrides (``None`` values are ignored, so a CLI can pass unset options through):
``clutter`` (``"uniform"``: a uniform model over the region with the same rate;
``"gmm"``: the preset's own mixture, or :func:`~mhtrack.scenario.overrides.default_mixture`
for uniform-clutter presets), ``clutter_rate`` (mean per scan per sensor), ``pd`` (every sensor),
``scans`` (number of scans from the first one), ``truth_sigma_v`` (truth process noise,
m/s²), ``sigma_range`` (m, polar sensors), ``heading_seed`` (``multiradar`` only).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.models.clutter import (
    ClutterPatch,
    GaussianMixtureClutter,
    Region,
    UniformClutter,
)
from mhtrack.models.sensors import CartesianSensor, PolarRadar, RotatingRadar
from mhtrack.scenario import _check as ck
from mhtrack.scenario import opensky
from mhtrack.scenario.geodesy import geodetic_to_enu
from mhtrack.scenario.overrides import OVERRIDES, apply_overrides, check_override_names
from mhtrack.scenario.spec import Scenario
from mhtrack.scenario.targets import RecordedTarget, Target
from mhtrack.scenario.trajectory import bridge_gaps

#: Names accepted by :func:`preset`.
PRESETS: tuple[str, ...] = ("crossing", "crossing-wide", "multiradar", "opensky",
                            "opensky-radars", "crossing-changing", "radars-clutter")
#: Keyword overrides accepted by :func:`preset`.
PRESET_OVERRIDES: tuple[str, ...] = (*OVERRIDES, "heading_seed")

# ------------------------------------------------------------------ crossing (P1 §3)
#: P1 Table 1: (state [x, vx, y, vy] at the birth scan, birth, death); ids 1–4.
CROSSING_TARGETS = (
    ((2000.0, -70.0, 3000.0, -60.0), 1, 80),
    ((-3000.0, 80.0, 2000.0, -100.0), 40, 90),
    ((-2000.0, 80.0, 3000.0, -100.0), 30, 90),
    ((3000.0, -70.0, 2000.0, -60.0), 1, 80),
)
#: P1 Table 2 clutter means (m) and printed diagonal covariance entries.
CROSSING_CLUTTER_MEANS = ((-2000.0, 1000.0), (700.0, 700.0), (400.0, 600.0), (500.0, 600.0))
CROSSING_CLUTTER_DIAG = (800.0, 1000.0, 1000.0, 1000.0)
CROSSING_CLUTTER_RATE = 40.0  # (ours) the papers give no clutter count


def _crossing(wide: bool, n_scans: int | None) -> Scenario:
    region = Region(-4000.0, 4000.0, -4000.0, 4000.0)
    diag = np.asarray(CROSSING_CLUTTER_DIAG)
    var = diag**2 if wide else diag
    clutter = GaussianMixtureClutter(
        region,
        CROSSING_CLUTTER_RATE,
        np.full(4, 0.25),
        np.asarray(CROSSING_CLUTTER_MEANS),
        var[:, None, None] * np.eye(2),
    )
    first = 1
    last = 90 if n_scans is None else first + n_scans - 1
    read = "standard deviations (m)" if wide else "variances (m²), as printed"
    return Scenario(
        name="crossing-wide" if wide else "crossing",
        description=(
            "P1 §3: four crossing targets, one Cartesian sensor (σw² = 1e4 m²), P_D = 0.9, "
            f"four-Gaussian clutter with the printed covariances read as {read}; "
            "λ = 40 per scan is our choice."
        ),
        region=region,
        T=1.0,
        scans=(first, last),
        targets=tuple(Target(i, s, b, d) for i, (s, b, d) in enumerate(CROSSING_TARGETS, 1)),
        sensors=(CartesianSensor(id=0, sigma=100.0),),
        pd=0.9,
        clutter=clutter,
    )


def _crossing_changing(n_scans: int | None) -> Scenario:
    import dataclasses

    from mhtrack.scenario.changing import changing_clutter

    base = _crossing(False, n_scans)
    return dataclasses.replace(
        base, name="crossing-changing",
        description=(
            "P1 §3's four crossing targets and sensor (σw² = 1e4 m², P_D = 0.9) in clutter "
            "whose seven Gaussian components appear, vanish, split, merge and drift over "
            "the run (λ = 40 per scan); the clutter is our choice."),
        clutter=changing_clutter(base.region))


# ------------------------------------------------------------------ multiradar (P2)
#: P2 §2.2/§3 initial positions (km), in the printed order; ids 1–10.
MULTIRADAR_START_KM = (
    (2.5, 2.3),
    (2.5, 2.5),
    (3.0, 3.0),
    (3.0, 2.0),
    (1.0, 1.5),
    (1.5, 4.0),
    (1.3, 3.8),
    (1.0, 1.3),
    (0.5, 2.7),
    (0.5, 3.0),
)
MULTIRADAR_SPEED = 200.0  # m/s (P2)
MULTIRADAR_HEADING_SEED = 2013  # (ours) headings ~ U[0°, 360°) from default_rng(2013)
MULTIRADAR_AREA = 2e8  # m², A₀ (P2)
MULTIRADAR_RADAR_RANGE = 10_000.0  # m from the area's centre (ours)
MULTIRADAR_RADAR_BEARINGS = (30.0, 150.0, 270.0)  # degrees clockwise from north (ours)


def multiradar_headings(seed: int = MULTIRADAR_HEADING_SEED) -> np.ndarray:
    """Headings (degrees clockwise from north) of the ten targets: ``U[0, 360)`` draws from
    ``np.random.default_rng(seed)`` — fixed inside the preset, whatever the simulation
    seed (our choice; P2 gives none)."""
    return np.random.default_rng(seed).uniform(0.0, 360.0, size=len(MULTIRADAR_START_KM))


def _multiradar(n_scans: int | None, heading_seed: int) -> Scenario:
    start = np.asarray(MULTIRADAR_START_KM) * 1000.0
    centre = 0.5 * (start.min(axis=0) + start.max(axis=0))
    half = 0.5 * np.sqrt(MULTIRADAR_AREA)
    region = Region(
        *(
            float(v)
            for v in (centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half)
        )
    )
    h = np.radians(multiradar_headings(heading_seed))
    v = MULTIRADAR_SPEED * np.column_stack((np.sin(h), np.cos(h)))
    first = 1
    last = 10 if n_scans is None else first + n_scans - 1
    targets = tuple(
        Target(i, (p[0], vv[0], p[1], vv[1]), first, last)
        for i, (p, vv) in enumerate(zip(start.tolist(), v.tolist(), strict=True), 1)
    )
    b = np.radians(MULTIRADAR_RADAR_BEARINGS)
    sites = centre + MULTIRADAR_RADAR_RANGE * np.column_stack((np.sin(b), np.cos(b)))
    radars = tuple(PolarRadar(i, (x, y), 20.0, 0.3) for i, (x, y) in enumerate(sites, 1))
    return Scenario(
        name="multiradar",
        description=(
            "P2 §2.2, §3: ten targets at 200 m/s from the printed positions, three polar "
            "radars (σr = 20 m, σθ = 0.3°), A0 = 2e8 m², uniform clutter λ = 50 per scan "
            "per radar. Headings (seed 2013), radar sites, P_D = 1 and 10 scans are ours."
        ),
        region=region,
        T=1.0,
        scans=(first, last),
        targets=targets,
        sensors=radars,
        pd=1.0,
        clutter=UniformClutter(region, 50.0),
    )


# ------------------------------------------------------------------ opensky
#: Radar sites (lat, lon) near the airports' reference points (ours).
OPENSKY_RADAR_SITES = {"Heathrow": (51.4775, -0.4614), "Manchester": (53.3539, -2.2750)}
#: Surveillance region (m, ENU about opensky.REFERENCE): the truth's extent padded by
#: 20 km and rounded out to 10 km (ours).
OPENSKY_REGION = Region(-280_000.0, 240_000.0, -250_000.0, 300_000.0)
#: Clutter mixture (ours): (lat, lon) centre, (σ_east, σ_north) m, weight — terminal
#: areas round Heathrow and Manchester and an elongated sea-clutter patch in the Channel.
OPENSKY_CLUTTER = (
    ((51.4775, -0.4614), (20_000.0, 20_000.0), 0.4),
    ((53.3539, -2.2750), (15_000.0, 15_000.0), 0.3),
    ((50.5, -2.0), (60_000.0, 15_000.0), 0.3),
)
OPENSKY_CLUTTER_BACKGROUND = 0.2
OPENSKY_CLUTTER_RATE = 20.0


def _enu2(latlon: tuple[float, float]) -> tuple[float, float]:
    e = geodetic_to_enu(latlon[0], latlon[1], *opensky.REFERENCE)
    return float(e[0]), float(e[1])


def _opensky(n_scans: int | None) -> Scenario:
    data = opensky.load_opensky()
    first = 0
    last = int(data.scan.max()) if n_scans is None else first + n_scans - 1
    region = OPENSKY_REGION
    means = np.array([_enu2(c) for c, _, _ in OPENSKY_CLUTTER])
    sd = np.array([s for _, s, _ in OPENSKY_CLUTTER])
    clutter = GaussianMixtureClutter(
        region,
        OPENSKY_CLUTTER_RATE,
        np.array([w for _, _, w in OPENSKY_CLUTTER]),
        means,
        sd[:, :, None] ** 2 * np.eye(2),
        background=OPENSKY_CLUTTER_BACKGROUND,
    )
    radars = tuple(
        PolarRadar(i, _enu2(site), 50.0, 0.15)
        for i, site in enumerate(OPENSKY_RADAR_SITES.values(), 1)
    )
    return Scenario(
        name="opensky",
        description=(
            "Real ADS-B aircraft (OpenSky Network, see mhtrack/data/ATTRIBUTION.md) in ENU "
            f"about lat/lon {opensky.REFERENCE}, 10 s scans; two polar radars near Heathrow "
            "and Manchester (σr = 50 m, σθ = 0.15°), P_D = 0.9, mixture clutter λ = 20 per "
            "scan per radar — sensors and clutter are our choice."
        ),
        region=region,
        T=opensky.PERIOD,
        scans=(first, last),
        targets=data.targets(first, last),
        sensors=radars,
        pd=0.9,
        clutter=clutter,
    )


# ------------------------------------------------------------------ opensky-radars
#: Rotating radars of ``opensky-radars`` (ours): name, (lat, lon) of a real radar site,
#: period (s), phase (°), σr (m), σθ (°), P_D, clutter rate per rotation (uniform in
#: range–azimuth) and one clutter patch (range m, bearing °, σr m, σθ °, rate per rotation).
OPENSKY_ROTATING_RADARS = (
    ("Heathrow", (51.4775, -0.4614), 4.0, 0.0, 30.0, 0.08, 0.95, 20.0,
     (110_000.0, 200.0, 15_000.0, 8.0, 8.0)),  # sea clutter, English Channel off the Solent
    ("Clee Hill", (52.3983, -2.5986), 10.0, 120.0, 50.0, 0.12, 0.90, 20.0,
     (25_000.0, 90.0, 5_000.0, 15.0, 6.0)),  # ground clutter, Wyre Forest / Birmingham side
    ("Waddington", (53.1662, -0.5239), 12.0, 240.0, 80.0, 0.20, 0.85, 20.0,
     (75_000.0, 95.0, 12_000.0, 10.0, 8.0)),  # sea clutter over the Wash
)
#: Instrumented range of the three radars (m, ours: an en-route radar's 160 NM).
OPENSKY_RADAR_MAX_RANGE = 300_000.0
#: Gaps in an aircraft's ADS-B reports up to this long (s) are bridged by the Hermite curve
#: between the reports around them: the aircraft kept flying while the receivers lost it,
#: and a radar would have seen it (ours; 17 of the data's 22 gaps, 20–120 s; the five
#: longer ones, 160–660 s, stay absences).
OPENSKY_MAX_GAP_S = 120.0


def _bridged(targets: tuple[RecordedTarget, ...]) -> tuple[RecordedTarget, ...]:
    """``targets`` with their gaps of at most :data:`OPENSKY_MAX_GAP_S` filled."""
    out = []
    for tg in targets:
        scans, states = bridge_gaps(np.asarray(tg.scans), np.asarray(tg.states),
                                    opensky.PERIOD, OPENSKY_MAX_GAP_S)
        out.append(RecordedTarget(tg.id, tuple(scans.tolist()), tuple(map(tuple,
                                                                          states.tolist()))))
    return tuple(out)


def _opensky_radars(n_scans: int | None) -> Scenario:
    from mhtrack.models.geodesy import LocalFrame  # pyproj: imported only when used

    data = opensky.load_opensky(frame=LocalFrame(*opensky.REFERENCE))
    first = 0
    last = int(data.scan.max()) if n_scans is None else first + n_scans - 1
    radars = tuple(
        RotatingRadar(id=i, lat=site[0], lon=site[1], period=period, phase=phase,
                      sigma_range=sr, sigma_bearing_deg=sb, max_range=OPENSKY_RADAR_MAX_RANGE,
                      clutter_rate=rate, clutter_patches=(ClutterPatch(*patch),))
        for i, (_, site, period, phase, sr, sb, _pd, rate, patch)
        in enumerate(OPENSKY_ROTATING_RADARS, 1)
    )
    return Scenario(
        name="opensky-radars",
        description=(
            "Real ADS-B aircraft (OpenSky Network, see mhtrack/data/ATTRIBUTION.md) seen by "
            "three rotating radars at Heathrow (4 s), Clee Hill (10 s) and Waddington "
            "(12 s), plots timed by the beam, range/bearing on WGS-84; sensors, clutter "
            "and frame origin (lat/lon "
            f"{opensky.REFERENCE}) are our choice."
        ),
        region=OPENSKY_REGION,
        T=opensky.PERIOD,
        scans=(first, last),
        targets=_bridged(data.targets(first, last)),
        sensors=radars,
        pd=tuple(r[6] for r in OPENSKY_ROTATING_RADARS),
        clutter=UniformClutter(OPENSKY_REGION, 0.0),
        origin=opensky.REFERENCE,
        truth_dt=1.0,
    )


# ------------------------------------------------------------------ preset()
def preset(name: str, **overrides: Any) -> Scenario:
    """The named reference scenario (see the module docstring), with overrides
    (:data:`PRESET_OVERRIDES`; :func:`apply_overrides` for all but ``heading_seed``).

    ``scans`` rebuilds the preset on the shorter or longer range: ``multiradar`` targets
    live on every scan, OpenSky trajectories are cut to the range.
    Raises ``ValueError`` for an unknown name, an unknown override or a bad value.
    """
    if name not in PRESETS:
        raise ValueError(f"unknown preset {name!r} (expected {', '.join(PRESETS)})")
    ov = {k: v for k, v in overrides.items() if v is not None}
    check_override_names(ov, PRESET_OVERRIDES)
    n_scans = ck.integer(ov["scans"], "scans", lo=1) if "scans" in ov else None
    if "heading_seed" in ov and name != "multiradar":
        raise ValueError("heading_seed: only the multiradar preset has headings to draw")
    if name in ("crossing", "crossing-wide"):
        s = _crossing(name == "crossing-wide", n_scans)
    elif name == "crossing-changing":
        s = _crossing_changing(n_scans)
    elif name == "multiradar":
        seed = ck.integer(ov.pop("heading_seed", MULTIRADAR_HEADING_SEED), "heading_seed", lo=0)
        s = _multiradar(n_scans, seed)
    elif name == "opensky":
        s = _opensky(n_scans)
    elif name == "radars-clutter":
        from mhtrack.scenario.scenes import radars_clutter

        s = radars_clutter(n_scans)
    else:
        s = _opensky_radars(n_scans)
    return apply_overrides(s, **ov)
