"""The dict/TOML form of a scenario: round trips (hypothesis) and key-path error messages."""

import copy
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mhtrack.errors import InputError
from mhtrack.models.clutter import (
    GaussianMixtureClutter,
    Region,
    TimeVaryingClutter,
    UniformClutter,
)
from mhtrack.models.sensors import CartesianSensor, PolarRadar
from mhtrack.scenario import (
    PRESETS,
    RecordedTarget,
    Scenario,
    Target,
    from_dict,
    load_scenario,
    preset,
    simulate,
)

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "examples" / "drifting-clutter.toml"
finite = dict(allow_nan=False, allow_infinity=False)


@st.composite
def mixtures(draw, region: Region, k: int) -> GaussianMixtureClutter:
    w, h = region.xmax - region.xmin, region.ymax - region.ymin
    means = [
        (draw(st.floats(region.xmin, region.xmax)), draw(st.floats(region.ymin, region.ymax)))
        for _ in range(k)
    ]
    covs = []
    for _ in range(k):
        a = draw(st.floats(min(w, h) / 100, min(w, h)))
        b = a * draw(st.floats(0.1, 10))  # well conditioned (cond <= 1e2 / (1 - r²))
        r = draw(st.floats(-0.9, 0.9))
        covs.append([[a * a, r * a * b], [r * a * b, b * b]])
    return GaussianMixtureClutter(
        region,
        draw(st.floats(0, 500, **finite)),
        np.array(draw(st.lists(st.floats(0.01, 1.0), min_size=k, max_size=k))),
        np.array(means),
        np.array(covs),
        background=draw(st.floats(0, 1)),
    )


@st.composite
def scenarios(draw) -> Scenario:
    x0, y0 = draw(st.floats(-1e5, 1e5)), draw(st.floats(-1e5, 1e5))
    region = Region(x0, x0 + draw(st.floats(1, 1e5)), y0, y0 + draw(st.floats(1, 1e5)))
    first = draw(st.integers(0, 50))
    last = first + draw(st.integers(0, 50))
    ids = draw(st.lists(st.integers(0, 99), min_size=1, max_size=3, unique=True))
    sensors = [
        CartesianSensor(i, draw(st.floats(0.1, 1e3)))
        if draw(st.booleans())
        else PolarRadar(
            i,
            (draw(st.floats(-1e5, 1e5)), draw(st.floats(-1e5, 1e5))),
            draw(st.floats(0.1, 100)),
            draw(st.floats(0.01, 5)),
        )
        for i in ids
    ]
    targets = []
    for tid in draw(st.lists(st.integers(0, 999), max_size=4, unique=True)):
        if draw(st.booleans()):
            b = draw(st.integers(0, 60))
            state = tuple(draw(st.floats(-1e4, 1e4)) for _ in range(4))
            targets.append(Target(tid, state, b, b + draw(st.integers(0, 60))))
        else:
            sc = sorted(draw(st.sets(st.integers(0, 80), min_size=1, max_size=5)))
            states = tuple(tuple(draw(st.floats(-1e4, 1e4)) for _ in range(4)) for _ in sc)
            targets.append(RecordedTarget(tid, tuple(sc), states))
    kind = draw(st.sampled_from(["uniform", "gmm", "time-varying"]))
    if kind == "uniform":
        clutter = UniformClutter(region, draw(st.floats(0, 500)))
    elif kind == "gmm":
        clutter = draw(mixtures(region, draw(st.integers(1, 3))))
    else:
        k = draw(st.integers(1, 2))
        frames = sorted(draw(st.sets(st.integers(0, 100), min_size=1, max_size=3)))
        clutter = TimeVaryingClutter(tuple((f, draw(mixtures(region, k))) for f in frames))
    return Scenario(
        name=draw(st.text(max_size=10)),
        region=region,
        T=draw(st.floats(1e-3, 100)),
        scans=(first, last),
        sensors=tuple(sensors),
        pd=tuple(draw(st.floats(0, 1, exclude_min=True)) for _ in sensors),
        clutter=clutter,
        targets=tuple(targets),
        truth_sigma_v=draw(st.floats(0, 20)),
        description=draw(st.text(max_size=20)),
    )


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenarios())
def test_dict_round_trip(s):
    d = s.to_dict()
    json.dumps(d, allow_nan=False)  # plain types only
    assert from_dict(d) == s
    assert from_dict(copy.deepcopy(d)).to_dict().keys() == d.keys()


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenarios())
def test_toml_round_trip(s):
    tomli_w = pytest.importorskip("tomli_w")
    assert from_dict(tomllib.loads(tomli_w.dumps(s.to_dict()))) == s


@pytest.mark.parametrize("name", PRESETS)
def test_presets_round_trip(name):
    s = preset(name)
    assert from_dict(s.to_dict()) == s


def test_equality_sees_every_field():
    s = preset("crossing")
    assert s == preset("crossing")
    import dataclasses

    assert s != dataclasses.replace(s, pd=0.8)
    assert s != dataclasses.replace(s, truth_sigma_v=1.0)
    assert s != preset("crossing-wide")
    assert s != "crossing"


def test_example_file_loads_and_simulates():
    s = load_scenario(EXAMPLE)
    assert isinstance(s.clutter, TimeVaryingClutter)
    assert s.clutter.at(1).background == 0.3
    assert s.targets[2].death == 60  # death defaults to the last scan
    sim = simulate(s, 0)
    c = sim.plots.origin == -1
    # the clutter swells: rate 10 → 60 per sensor, two sensors
    early = c[sim.plots.scan <= 10].sum() / 10
    late = c[sim.plots.scan > 50].sum() / 10
    assert early < 2 * 20 < late
    # and drifts: first component's mean moves from (-3000, -3000) to (3000, 3000)
    assert s.clutter.at(60).means[0].tolist() == [3000.0, 3000.0]
    assert len(sim.plots.scan_times[0]) == 60


def _base() -> dict:
    with EXAMPLE.open("rb") as f:
        return tomllib.load(f)


def _set(d, path, value):
    *head, last = path
    for k in head:
        d = d[k]
    if value is _DEL:
        del d[last]
    else:
        d[last] = value


_DEL = object()

BAD = [
    (("targets", 2, "birth"), 70, r"^targets\[2\]\.birth: must be <= death \(70 > 60\)"),
    (
        ("clutter", "kind"),
        "foo",
        r"^clutter\.kind: unknown 'foo' \(expected uniform, gmm, time-varying\)",
    ),
    (("foo",), 1, r"^scenario: unknown key 'foo' \(allowed: "),
    (("sensors", 0, "sigmaa"), 1.0, r"^sensors\[0\]: unknown key 'sigmaa'"),
    (("seed",), -1, r"^seed: must be >= 0"),
    (("T",), "1", r"^T: expected a number, got str"),
    (("T",), float("nan"), r"^T: must be finite"),
    (("T",), 0.0, r"^T: must be > 0"),
    (("T",), _DEL, r"^T: missing"),
    (("scans",), [5, 3], r"^scans: first must be <= last"),
    (("scans",), [1.0, 3], r"^scans\[0\]: expected an integer, got float"),
    (("region", "xmax"), -6000.0, r"^region\.xmax: must be > xmin"),
    (("region", "ymin"), float("inf"), r"^region\.ymin: must be finite"),
    (("sensors", 1, "id"), 0, r"^sensors\[1\]\.id: duplicate id 0"),
    (("sensors", 1, "id"), True, r"^sensors\[1\]\.id: expected an integer, got bool"),
    (("sensors", 0, "pd"), 1.5, r"^sensors\[0\]\.pd: must be in \(0, 1\]"),
    (
        ("sensors", 1, "kind"),
        "sonar",
        r"^sensors\[1\]\.kind: unknown 'sonar' \(expected cartesian, polar\)",
    ),
    (("sensors", 1, "position"), [1.0], r"^sensors\[1\]\.position: expected 2 elements"),
    (("sensors", 0, "sigma"), -1.0, r"^sensors\[0\]\.sigma: must be > 0"),
    (("targets", 0, "state"), [1.0, 2.0, 3.0], r"^targets\[0\]\.state: expected 4 elements"),
    (("targets", 0, "state", 1), float("-inf"), r"^targets\[0\]\.state\[1\]: must be finite"),
    (("targets", 1, "id"), 1, r"^targets\[1\]\.id: duplicate id 1"),
    (("targets", 1, "velocity"), [1, 2], r"^targets\[1\]: unknown key 'velocity'"),
    (
        ("clutter", "keyframes", 1, "covariances", 1),
        [[1.0, 0.0], [0.0, -1.0]],
        r"^clutter\.keyframes\[1\]\.covariances\[1\]: must be symmetric positive definite",
    ),
    (
        ("clutter", "keyframes", 1, "covariances", 0),
        [[1e8, 0.0], [0.0, 1e-3]],
        r"^clutter\.keyframes\[1\]\.covariances\[0\]: too ill-conditioned",
    ),
    (
        ("clutter", "keyframes", 1, "covariances", 0),
        [[1.0, 0.5], [0.0, 1.0]],
        r"^clutter\.keyframes\[1\]\.covariances\[0\]: must be symmetric",
    ),
    (
        ("clutter", "keyframes", 1, "weights"),
        [1.0],
        r"^clutter\.keyframes\[1\]\.weights: expected 2 components like keyframes\[0\], got 1",
    ),
    (
        ("clutter", "keyframes", 1, "scan"),
        1,
        r"^clutter\.keyframes\[1\]\.scan: must be > the previous keyframe's scan",
    ),
    (
        ("clutter", "keyframes", 0, "means", 1),
        [0.0, "x"],
        r"^clutter\.keyframes\[0\]\.means\[1\]\[1\]: expected a number",
    ),
    (
        ("clutter", "keyframes", 0, "background"),
        2.0,
        r"^clutter\.keyframes\[0\]\.background: must be in \[0, 1\]",
    ),
    (("clutter", "keyframes", 0, "rate"), -3.0, r"^clutter\.keyframes\[0\]\.rate: must be >= 0"),
    (("clutter", "keyframes"), [], r"^clutter\.keyframes: at least one keyframe"),
    (("clutter",), {"kind": "uniform"}, r"^clutter\.rate: missing"),
    (
        ("clutter",),
        {
            "kind": "gmm",
            "rate": 1.0,
            "weights": [1.0],
            "means": [[1e9, 1e9]],
            "covariances": [[[1.0, 0.0], [0.0, 1.0]]],
        },
        r"^clutter: clutter mixture has no mass inside the region",
    ),
    # limits (MAX_SCANS, MAX_PLOTS, MAX_T, MAX_SIGMA, MAX_SIGMA_BEARING_DEG, MAX_COORDINATE,
    # MAX_SPEED): refused up front instead of running out of memory or overflowing
    (
        ("scans",),
        [1, 10**9],
        r"^scans: \[1, 1000000000\] is 1000000000 scans, more than "
        r"the maximum 100000 \(MAX_SCANS\)",
    ),
    (("scans",), [1, 2**63 - 1], r"^scans: .* more than the maximum 100000 \(MAX_SCANS\)"),
    (
        ("clutter", "keyframes", 1, "rate"),
        1e12,
        r"^clutter\.keyframes\[1\]\.rate: a simulation would give about .* plots .* more "
        r"than the maximum 5e7 \(MAX_PLOTS\)",
    ),
    (("T",), 1e300, r"^T: must be <= 1e6 s, got 1e\+300"),
    (("truth_sigma_v",), 1e300, r"^truth_sigma_v: must be <= 1e4 m/s², got"),
    (("sensors", 0, "sigma"), 1e200, r"^sensors\[0\]\.sigma: must be <= 1e6 m, got 1e\+200"),
    (("sensors", 1, "sigma_range"), 1e7, r"^sensors\[1\]\.sigma_range: must be <= 1e6 m"),
    (
        ("sensors", 1, "sigma_bearing_deg"),
        1000.0,
        r"^sensors\[1\]\.sigma_bearing_deg: must be <= 30 degrees, got 1000\.0",
    ),
    (("sensors", 1, "position", 0), 1e10, r"^sensors\[1\]\.position\[0\]: must be within ±1e9 m"),
    (("region", "xmin"), -1e300, r"^region\.xmin: must be within ±1e9 m, got -1e\+300"),
    (("region", "ymax"), 1e300, r"^region\.ymax: must be within ±1e9 m"),
    (("targets", 0, "state", 2), 2e9, r"^targets\[0\]\.state\[2\]: must be within ±1e9 m"),
    (("targets", 0, "state", 1), -7e5, r"^targets\[0\]\.state\[1\]: must be within ±1e5 m/s"),
    (
        ("targets", 0),
        {"id": 4, "scans": [3], "states": [[0, 0, 0, 1e300]]},
        r"^targets\[0\]\.states\[0\]\[3\]: must be within ±1e5 m/s",
    ),
    (("targets",), {"id": 1}, r"^targets: expected a list"),
    (
        ("targets", 0),
        {"id": 4, "scans": [3, 2], "states": [[0, 0, 0, 0]] * 2},
        r"^targets\[0\]\.scans\[1\]: must be > the previous scan",
    ),
    (
        ("targets", 0),
        {"id": 4, "scans": [3, 4], "states": [[0, 0, 0, 0]]},
        r"^targets\[0\]\.states: expected 2 elements",
    ),
]


@pytest.mark.parametrize(
    ("path", "value", "message"), BAD, ids=[".".join(map(str, p)) for p, _, _ in BAD]
)
def test_validation_errors_name_the_key_path(path, value, message):
    d = _base()
    from_dict(d)  # the unmodified example is valid
    _set(d, path, value)
    with pytest.raises(ValueError, match=message):
        from_dict(d)


def test_load_scenario_errors_name_the_file(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text('T = "x"\n')
    with pytest.raises(InputError, match=r"bad\.toml: clutter: missing") as info:
        load_scenario(f)
    assert (info.value.file, info.value.key) == (str(f), "clutter")
    text = EXAMPLE.read_text()
    assert "\nT = 1.0\n" in text
    f.write_text(text.replace("\nT = 1.0\n", "\nT = -1.0\n"))
    with pytest.raises(InputError) as info:
        load_scenario(f)
    assert str(info.value).startswith(f"{f}: T: ") and info.value.key == "T"
    f.write_text("T = = 1\n")
    with pytest.raises(InputError) as info:
        load_scenario(f)
    assert str(info.value) == f"{f}, line 1, column 5: Invalid value"
    assert info.value.line == 1
    with pytest.raises(InputError) as info:
        load_scenario(tmp_path / "none.toml")
    assert str(info.value) == f"{tmp_path / 'none.toml'}: no such file"


def test_load_scenario_bad_utf8_names_the_file_and_bom_is_accepted(tmp_path):
    text = EXAMPLE.read_bytes()
    f = tmp_path / "latin1.toml"
    f.write_bytes(text.replace(b'name = "drifting-clutter"', b'name = "caf\xe9"'))
    with pytest.raises(InputError) as info:
        load_scenario(f)
    assert str(info.value) == f"{f}, line 6: not valid UTF-8 text (byte 0xe9)"
    f.write_bytes(bytes(range(256)))
    with pytest.raises(InputError, match=r"latin1\.toml, line 2: not valid UTF-8 text "):
        load_scenario(f)
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + text)
    assert load_scenario(bom) == load_scenario(EXAMPLE)
    from mhtrack.io import read_toml

    assert read_toml(bom) == read_toml(EXAMPLE)


def test_sensor_and_scenario_constructors_enforce_the_limits():
    import dataclasses

    with pytest.raises(ValueError, match=r"sensor 0: sigma must be > 0 and <= 1e6 m, got 1e\+200"):
        CartesianSensor(0, 1e200)
    with pytest.raises(ValueError, match=r"sensor 1: sigma_range must be > 0 and <= 1e6 m"):
        PolarRadar(1, (0.0, 0.0), 1e7, 0.3)
    with pytest.raises(ValueError, match=r"sensor 1: sigma_bearing_deg must be > 0 and <= 30"):
        PolarRadar(1, (0.0, 0.0), 20.0, 1000.0)
    with pytest.raises(ValueError, match=r"sensor 1: position must be two finite coordinates"):
        PolarRadar(1, (1e300, 0.0))
    s = preset("crossing", scans=3)
    with pytest.raises(ValueError, match=r"^T: must be <= 1e6 s"):
        dataclasses.replace(s, T=1e300)
    with pytest.raises(ValueError, match=r"^region\.xmin: must be within ±1e9 m"):
        big = Region(-1e300, 1e300, -1.0, 1.0)
        dataclasses.replace(s, region=big, clutter=UniformClutter(big, 1.0))
    with pytest.raises(ValueError, match=r"^targets\[0\]\.state\[0\]: must be within ±1e9 m"):
        dataclasses.replace(s, targets=(Target(1, (1e12, 0.0, 0.0, 0.0), 1, 3),))
    with pytest.raises(ValueError, match=r"^scans: \[1, 100001\] is 100001 scans"):
        dataclasses.replace(s, scans=(1, 100_001))


def test_scenario_constructor_validates():
    s = preset("crossing", scans=3)
    import dataclasses

    with pytest.raises(ValueError, match=r"pd: expected one per sensor \(1\), got 2"):
        dataclasses.replace(s, pd=(0.5, 0.5))
    with pytest.raises(ValueError, match="clutter: region"):
        dataclasses.replace(s, clutter=UniformClutter(Region(0, 1, 0, 1), 1.0))
    with pytest.raises(ValueError, match=r"sensors: at least one"):
        dataclasses.replace(s, sensors=())
    with pytest.raises(ValueError, match=r"scans\[0\]: must be >= 0"):
        dataclasses.replace(s, scans=(-1, 3))


def test_docs_toml_example_is_valid():
    text = (EXAMPLE.parents[1] / "scenarios.md").read_text(encoding="utf-8")
    blocks = [b.split("```", 1)[0] for b in text.split("```toml\n")[1:]]
    block = next(b for b in blocks if 'name = "drifting-clutter"' in b)
    s = from_dict(tomllib.loads(block))
    assert s.name == "drifting-clutter" and len(s.sensors) == 2
    assert isinstance(s.clutter, TimeVaryingClutter)
    # the rotating-radar fragment completes to a valid scenario
    frag = next(b for b in blocks if "period = 6.0" in b)
    d = tomllib.loads(frag)
    d.update(T=1.0, scans=[0, 10], region={"xmin": -1e5, "xmax": 1e5, "ymin": -1e5,
                                           "ymax": 1e5})
    assert from_dict(d).rotating


def test_cli_record_with_seed_reads_back():
    s = preset("multiradar")
    assert from_dict({"seed": 12, **s.to_dict()}) == s
