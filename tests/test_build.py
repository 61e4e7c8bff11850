"""The tracker builder (``mhtrack.build``): every name builds its part, the defaults follow
the scenario, the P_D cap, the plots' area and the κ check by hand."""

import subprocess
import sys

import numpy as np
import pytest

from mhtrack import build, names
from mhtrack.clutter import AGMMClutter, GMMClutter, KnownClutter
from mhtrack.initiation import AdaptiveKMeansFusion, HoughInitiator, KMeansFusion, LogicInitiator
from mhtrack.mht import MHTConfig
from mhtrack.scenario import preset
from mhtrack.scenario.spec import from_dict


def test_mappings_cover_exactly_the_names():
    assert set(build.TRACKER_ESTIMATORS) == set(names.TRACKERS)
    assert set(build.TRACKER_ESTIMATORS.values()) <= set(names.CLUTTER_ESTIMATORS)
    assert tuple(build.CLUTTER_ESTIMATOR_CLASSES) == names.CLUTTER_ESTIMATORS
    assert set(build.INITIATOR_CLASSES) == set(names.INITIATORS)
    assert (names.EVERY_PLOT, *names.INITIATORS) == names.BIRTHS
    assert set(build.TRACKER_FUSERS) == set(names.TRACKER_FUSIONS)
    assert set(build.INITIATION_FUSER_CLASSES) == set(names.INITIATION_FUSIONS)


@pytest.mark.parametrize(("name", "cls"), [("mht", KnownClutter), ("mht-gmm", GMMClutter),
                                           ("mht-agmm", AGMMClutter)])
def test_every_tracker_builds_with_every_birth(name, cls):
    for birth in names.BIRTHS:
        trk = build.make_tracker(name, birth=birth, theta_deg=30.0)
        assert type(trk.clutter) is cls
        assert (trk.config.birth, trk.config.birth_theta_deg) == (birth, 30.0)
    with pytest.raises(ValueError, match=r"unknown tracker 'nope'.*mht, mht-gmm, mht-agmm"):
        build.make_tracker("nope")


def test_known_clutter_density_only_for_mht():
    assert build.make_tracker("mht").clutter.kappa == 1e-9  # P1 §3
    assert build.make_tracker("mht", clutter_density=2e-8).clutter.kappa == 2e-8
    assert type(build.make_tracker("mht-agmm", clutter_density=2e-8).clutter) is AGMMClutter
    assert build.takes_clutter_density("mht")
    assert not build.takes_clutter_density("mht-gmm")
    assert not build.takes_clutter_density("mht-agmm")


def test_clutter_estimators_by_name():
    assert build.make_clutter_estimator("known").kappa == build.DEFAULT_CLUTTER_DENSITY
    assert build.make_clutter_estimator("known", kappa=3e-9, window=4).kappa == 3e-9
    for name in names.CLUTTER_ESTIMATORS:
        assert type(build.make_clutter_estimator(name)) is build.CLUTTER_ESTIMATOR_CLASSES[name]
    gmm = build.make_clutter_estimator("gmm", window=2, n_components=None)
    assert gmm.window == 2 and gmm.n_components == GMMClutter().n_components
    with pytest.raises(ValueError, match="unknown clutter estimator 'kde'"):
        build.make_clutter_estimator("kde")


def test_initiators_by_name():
    logic = build.make_initiator("logic", theta_deg=33.0)
    assert type(logic) is LogicInitiator and logic.angle_limit_deg is None  # plain 3/4
    mod = build.make_initiator("modified-logic", theta_deg=33.0, gate_radius=250.0)
    assert (mod.angle_limit_deg, mod.gate_radius) == (33.0, 250.0)
    hough = build.make_initiator("hough", votes=3)
    assert type(hough) is HoughInitiator and not hough.modified and hough.votes == 3
    assert hough.angle_limit_deg == 20.0  # P2's θ by default
    assert build.make_initiator("modified-hough").modified
    with pytest.raises(ValueError, match="unknown initiation method 'magic'"):
        build.make_initiator("magic")


def test_fusers_by_name():
    fuser = build.TRACKER_FUSERS["adaptive-kmeans"]()
    assert isinstance(fuser, AdaptiveKMeansFusion)
    assert (fuser.weighting, fuser.consistency) == ("information", 0.9999)
    assert build.TRACKER_FUSERS["none"] is None
    assert build.INITIATION_FUSER_CLASSES["kmeans"] is KMeansFusion
    assert (build.default_fusion(1), build.default_fusion(3)) == ("none", "adaptive-kmeans")


def test_default_config_follows_one_cartesian_sensor():
    d = preset("crossing").to_dict()
    d["sensors"][0].update(pd=0.7, sigma=20.0)
    cfg = build.default_config(from_dict(d))
    assert (cfg.p_detection, cfg.sigma_w) == (0.7, 20.0)
    # P1's crossing: P_D 0.9, σ 100 m, λv 1e-7 over its 6.4e7 m² — P1's own values
    cfg = build.default_config(preset("crossing"))
    assert (cfg.p_detection, cfg.sigma_w) == (0.9, 100.0)
    assert cfg.new_target_density == pytest.approx(1e-7)
    # several radars: fused plots, P1's 0.9 kept whatever the radars' P_D
    assert build.default_config(preset("multiradar", pd=0.6)).p_detection == 0.9
    assert build.default_config() == MHTConfig()
    assert build.default_config(area=6.4e9).new_target_density == pytest.approx(1e-9)


def test_pd_cap():
    assert build.capped_pd(0.95) == 0.95
    assert build.capped_pd(1.0) == build.MAX_TRACKER_PD == 0.999
    d = preset("crossing").to_dict()
    d["sensors"][0]["pd"] = 1.0
    assert build.default_config(from_dict(d)).p_detection == 0.999


def test_config_with_ignores_none():
    cfg = build.config_with(None, n_scan=5, sigma_v=None)
    assert cfg == MHTConfig(n_scan=5)
    assert build.config_with(cfg, p_detection=0.8) == MHTConfig(n_scan=5, p_detection=0.8)


def test_birth_density_for_area():
    assert build.birth_density_for_area(6.4e7) == pytest.approx(1e-7)  # P1 §3
    for bad in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(ValueError, match="area"):
            build.birth_density_for_area(bad)


def test_plots_area_by_hand():
    # 1001 plots evenly on x in [0, 1000], y in [0, 500]: the 0.5 %–99.5 % box is
    # [5, 995] × [2.5, 497.5]
    x, y = np.linspace(0, 1000, 1001), np.linspace(0, 500, 1001)
    box = build.plots_area(x, y)
    assert (box.x0, box.x1, box.y0, box.y1) == pytest.approx((5, 995, 2.5, 497.5))
    assert box.area == pytest.approx(990 * 495) and box.n_far == 0
    # one wild plot 1e8 m east moves the box by a tenth of a cell and is reported
    wild = build.plots_area(np.append(x, 1e8), np.append(y, 250.0))
    assert wild.n_far == 1 and wild.area == pytest.approx(box.area, rel=1e-2)
    # all plots on one point: a 1 m × 1 m box
    assert build.plots_area(np.zeros(5), np.zeros(5)).area == 1.0


def test_known_kappa_mismatch():
    # 10 uniform plots per scan over 6.4e7 m²: 1.5625e-7 per m², 156× P1's κ
    dense = preset("crossing", clutter="uniform", clutter_rate=10.0)
    assert build.known_kappa_mismatch(dense) == pytest.approx(1.5625e-7)
    assert build.known_kappa_mismatch(dense, kappa=1e-7) is None
    # 0.32 plots per scan: 5e-9 per m², within 10× of 1e-9
    assert build.known_kappa_mismatch(preset("crossing", clutter="uniform",
                                             clutter_rate=0.32)) is None
    assert build.known_kappa_mismatch(preset("crossing", clutter="uniform",
                                             clutter_rate=0.0)) is None


def test_builder_imports_no_later_layer():
    code = ("import sys, mhtrack.build; print(sorted({k.split('.')[1] for k in sys.modules "
            "if k.startswith('mhtrack.')} & {'metrics', 'experiments', 'plotting', 'cli', "
            "'reports'}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]", out.stdout


def _continue(trk, scans):
    return [trk.step(s) for s in scans]


@pytest.mark.parametrize("name", ["mht", "mht-gmm", "mht-agmm"])
def test_load_tracker_needs_no_parts_and_continues_identically(tmp_path, name):
    from mhtrack.scenario import simulate

    scans = list(simulate(preset("crossing", scans=14), seed=2).plots.scans())
    trk = build.make_tracker(name, build.default_config(preset("crossing")),
                             clutter_density=3e-9 if name == "mht" else None)
    _continue(trk, scans[:8])
    trk.save(tmp_path / "s.npz")
    back = build.load_tracker(tmp_path / "s.npz")
    assert type(back.clutter) is type(trk.clutter) and back.recipe == trk.recipe
    for a, b in zip(_continue(trk, scans[8:]), _continue(back, scans[8:]), strict=True):
        assert a.track_id.tolist() == b.track_id.tolist()
        assert a.x.tolist() == b.x.tolist() and a.y.tolist() == b.y.tolist()


def test_load_tracker_rebuilds_radars_and_polar_clutter(tmp_path):
    from async_fixture import simulate_async

    from mhtrack.clutter.polar import PolarClutter

    sim = simulate_async(duration=60.0)
    frames = list(sim.plots.scans())
    trk = build.make_tracker("mht-agmm", sensors=sim.sensors)
    _continue(trk, frames[: len(frames) // 2])
    trk.save(tmp_path / "a.npz")
    back = build.load_tracker(tmp_path / "a.npz")
    assert isinstance(back.clutter.estimator(1), PolarClutter)
    assert back.coverage.sensors == sim.sensors
    rest = frames[len(frames) // 2:]
    for a, b in zip(_continue(trk, rest), _continue(back, rest), strict=True):
        assert a.track_id.tolist() == b.track_id.tolist() and a.x.tolist() == b.x.tolist()


def test_load_tracker_refuses_a_hand_assembled_tracker(tmp_path):
    from mhtrack.clutter import GMMClutter
    from mhtrack.errors import InputError
    from mhtrack.mht import MHTTracker

    MHTTracker(MHTConfig(), GMMClutter()).save(tmp_path / "h.npz")
    # an InputError (a ValueError) naming the file and member: a state whose recipe was
    # deleted looks the same
    with pytest.raises(InputError, match=r"h\.npz, member 'meta': .*no recipe"):
        build.load_tracker(tmp_path / "h.npz")
