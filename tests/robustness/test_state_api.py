"""The Python API on hostile state files and out-of-bound values (issue 33): every damaged
state that ``mhtrack.build.load_tracker`` or ``MHTTracker.load`` reads raises
:class:`~mhtrack.errors.InputError` naming the file and the field — at loading, never
later at ``step`` — and a valid state still round-trips bit for bit.

The cases listed are those an adversarial run found on the code before this change
(OverflowError, KeyError, a ValueError blaming 'recipe', a broadcasting error at ``step``
after null mixture weights); the property test mutates the JSON of real saved states
(GMM and AGMM estimators, per-radar polar clutter) at every path with hostile values."""

from __future__ import annotations

import json
import math
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mhtrack import build
from mhtrack.errors import InputError
from mhtrack.mht import MHTTracker
from mhtrack.records import Scan
from mhtrack.scenario import preset, simulate

sys.path.insert(0, str(Path(__file__).parents[1] / "mht"))
from async_fixture import simulate_async
from npz_members import members as read_members  # tests/helpers
from npz_members import write_members

FUZZ = settings(derandomize=True, deadline=None, max_examples=150, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])


@pytest.fixture(scope="module")
def states(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Saved states (members, the scans that follow): an AGMM tracker on the crossing
    preset, and a per-radar polar AGMM tracker on rotating radars."""
    out: dict[str, Any] = {}
    folder = tmp_path_factory.mktemp("states")
    scans = list(simulate(preset("crossing", scans=10), seed=2).plots.scans())
    trk = build.make_tracker("mht-agmm", build.default_config(preset("crossing")))
    for s in scans[:7]:
        trk.step(s)
    trk.save(folder / "agmm.npz")
    out["agmm"] = (read_members(folder / "agmm.npz"), scans[7:])
    sim = simulate_async(duration=40.0)
    frames = list(sim.plots.scans())
    trk = build.make_tracker("mht-agmm", sensors=sim.sensors)
    for f in frames[: len(frames) // 2]:
        trk.step(f)
    trk.save(folder / "async.npz")
    out["async"] = (read_members(folder / "async.npz"), frames[len(frames) // 2:][:3])
    return out


def _meta(members: dict[str, np.ndarray]) -> dict[str, Any]:
    return json.loads(str(members["meta"]))


def _with_meta(members: dict[str, np.ndarray], meta: dict[str, Any]) -> dict[str, np.ndarray]:
    return {**members, "meta": np.array(json.dumps(meta))}


def _load_and_step(path: Path, scans: list[Scan]) -> None:
    """Load then step: only InputError (one line naming the file) may come out."""
    try:
        trk = build.load_tracker(path)
    except InputError as e:
        assert str(e).startswith(str(path)) and "\n" not in str(e), str(e)
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for s in scans:
            trk.step(s)


def _set(meta: dict[str, Any], keys: tuple[Any, ...], value: Any) -> None:
    obj = meta
    for k in keys[:-1]:
        obj = obj[k]
    if value is _DROP:
        del obj[keys[-1]]
    else:
        obj[keys[-1]] = value


_DROP = object()

# (state, path in meta, value, expected words): each raised something else before
CASES = [
    ("agmm", ("last_time",), _DROP, "field 'last_time': missing"),  # KeyError
    ("agmm", ("last_index",), _DROP, "field 'last_index': missing"),  # KeyError
    ("agmm", ("config", "sigma_w"), 1e308, "field 'config.sigma_w'"),  # OverflowError
    ("agmm", ("config", "imm_sigma_v"), 1e308, "field 'config.imm_sigma_v'"),  # at step
    ("agmm", ("config", "sigma_v"), None, "cannot be restored (MHTConfig.sigma_v"),
    # a ValueError from MHTTracker.load: 'saved with 2 IMM models, the motion model ... 0'
    ("agmm", ("config", "imm_sigma_v"), 0, "member 'leaves__mu': 2 IMM model probabilities"),
    ("agmm", ("recipe", "name"), None, "field 'recipe.name'"),  # ValueError 'recipe'
    ("agmm", ("recipe", "clutter_params"), "x", "field 'recipe.clutter_params'"),
    ("agmm", ("recipe", "clutter_params"), {"bogus": 1}, "field 'recipe.clutter_params'"),
    ("agmm", ("recipe", "clutter_density"), 10**30, "field 'recipe.clutter_density'"),
    ("agmm", ("recipe", "sensors"), [], "field 'recipe.sensors'"),
    ("agmm", ("clutter_name",), "x", "field 'clutter_name'"),  # plain ValueError
    ("agmm", ("clutter_state", "kept"), 10**30, "clutter_state"),  # OverflowError
    ("agmm", ("clutter_state", "n_updates"), -1, "clutter_state.n_updates"),  # at step
    # null mixture weights: a broadcasting ValueError at step before
    ("agmm", ("clutter_state", "mixture", "weights"), None, "clutter_state.mixture.weights"),
    ("agmm", ("clutter_state", "mixture", "means"), [], "clutter_state.mixture.means"),
    ("async", ("clutter_state", "inner", 0, "inner", "count"), -1, "clutter_state.count"),
    ("async", ("clutter_state", "inner", 0, "inner", "mixture", "background_box"), [],
     "clutter_state.mixture.background_box"),
    # a KeyError at step: pending frames of a radar without their start time
    ("async", ("clutter_state", "start"), {}, "clutter_state.start"),
]


@pytest.mark.parametrize(("state", "keys", "value", "words"), CASES,
                         ids=[f"{c[0]}-{'.'.join(map(str, c[1]))}" for c in CASES])
def test_damaged_meta_raises_input_error_at_loading(tmp_path: Path, states: dict[str, Any],
                                                    state: str, keys: tuple[Any, ...],
                                                    value: Any, words: str) -> None:
    members, _ = states[state]
    meta = _meta(members)
    try:
        _set(meta, keys, value)
    except (KeyError, IndexError, TypeError):
        pytest.skip("that state has no such field")
    path = write_members(tmp_path / "s.npz", _with_meta(members, meta))
    with pytest.raises(InputError) as e:
        build.load_tracker(path)
    assert str(e.value).startswith(f"{path}, member '"), str(e.value)
    assert words in str(e.value)


def test_leaf_time_beyond_the_bound_is_refused(tmp_path: Path, states: dict[str, Any]) -> None:
    """A leaf time of 1e300 made ``step`` raise OverflowError (``exp(−dt/τ)``)."""
    members, _ = states["agmm"]
    bad = {**members, "leaves__time": np.full_like(members["leaves__time"], 1e300)}
    with pytest.raises(InputError, match=r"member 'leaves__time': leaf times must be"):
        build.load_tracker(write_members(tmp_path / "s.npz", bad))


def test_scan_time_beyond_the_bound_is_an_input_error() -> None:
    """A scan at 1e100 s raised OverflowError inside ``step``."""
    trk = build.make_tracker("mht-agmm", build.default_config(preset("crossing")))
    scan = Scan(0, 1e100, np.zeros((1, 2)), np.zeros(1, np.int64), np.arange(1))
    with pytest.raises(InputError, match=r"scan 0: time 1e\+100 s is beyond ±1e\+12 s") as e:
        trk.step(scan)
    assert e.value.key == "time"


def test_valid_states_round_trip_bit_for_bit(tmp_path: Path, states: dict[str, Any]) -> None:
    """Loading and saving again gives the same members, value for value; and the loaded
    tracker continues as the one that was saved (the reference: a second load)."""
    for name, (members, scans) in states.items():
        path = write_members(tmp_path / f"{name}.npz", members)
        trk = build.load_tracker(path)
        trk.save(tmp_path / f"{name}2.npz")
        again = read_members(tmp_path / f"{name}2.npz")
        assert sorted(again) == sorted(members)
        for k, a in members.items():
            assert a.dtype == again[k].dtype and np.array_equal(
                a, again[k], equal_nan=a.dtype.kind == "f"), k
        other = build.load_tracker(path)
        for s in scans:
            a, b = trk.step(s), other.step(s)
            assert a.track_id.tolist() == b.track_id.tolist() and a.x.tolist() == b.x.tolist()


def _paths(obj: Any, at: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [at] if at else []
    if isinstance(obj, dict):
        for k, v in obj.items():
            out += _paths(v, (*at, k))
    elif isinstance(obj, list):
        for i, v in enumerate(obj[:3]):
            out += _paths(v, (*at, i))
    return out


HOSTILE = st.sampled_from([_DROP, None, 10**30, -(2**63), -1, 0, 1e308, -1e308, 1e100,
                           0.5, "x", [], {}, True, [1.0, 2.0], {"__ndarray__": "leaves__x"}])


@FUZZ
@given(state=st.sampled_from(["agmm", "async"]), pick=st.integers(0, 10**6), value=HOSTILE)
def test_any_meta_field_made_hostile_loads_or_raises_input_error(
        tmp_path: Path, states: dict[str, Any], state: str, pick: int, value: Any) -> None:
    """Any field of ``meta`` (configuration, recipe, counters, the estimator's state)
    replaced or dropped: ``load_tracker`` and two steps raise nothing but InputError."""
    members, scans = states[state]
    meta = _meta(members)
    paths = _paths(meta)
    _set(meta, paths[pick % len(paths)], value)
    _load_and_step(write_members(tmp_path / "h.npz", _with_meta(members, meta)), scans[:2])


def _hostile_array(kind: int, a: np.ndarray) -> np.ndarray | None:
    with np.errstate(all="ignore"):
        negative = ~a if a.dtype == bool else -np.abs(a) - 1
        return [None, a[:0], np.full(a.shape, np.nan), np.zeros_like(a), negative,
                np.full(a.shape, 2**62, np.int64), np.full(a.shape, 1e300),
                a.astype(np.float32) if a.dtype.kind in "fiu" else a, a[:1], np.array(3),
                np.concatenate([a, a[:1]]) if a.ndim and a.size else a][kind]


@FUZZ
@given(state=st.sampled_from(["agmm", "async"]), pick=st.integers(0, 10**6),
       kind=st.integers(0, 10))
def test_any_array_member_made_hostile_loads_or_raises_input_error(
        tmp_path: Path, states: dict[str, Any], state: str, pick: int, kind: int) -> None:
    """Any array member dropped, emptied, NaN, negative, huge, of another dtype or shape:
    only InputError, at loading or never."""
    members, scans = states[state]
    names = sorted(k for k in members if k != "meta")
    name = names[pick % len(names)]
    changed = dict(members)
    new = _hostile_array(kind, members[name])
    if new is None:
        del changed[name]
    else:
        changed[name] = new
    _load_and_step(write_members(tmp_path / "h.npz", changed), scans[:2])


def test_tracker_load_names_a_wrong_estimator_as_input_error(
        tmp_path: Path, states: dict[str, Any]) -> None:
    """``MHTTracker.load`` with the file's estimator name changed: an InputError (still a
    ValueError, as documented) naming the file and the field."""
    members, _ = states["agmm"]
    meta = _meta(members)
    meta["clutter_name"] = "known"
    path = write_members(tmp_path / "s.npz", _with_meta(members, meta))
    from mhtrack.clutter import AGMMClutter

    with pytest.raises(InputError, match=r"member 'meta': field 'clutter_name'"):
        MHTTracker.load(path, AGMMClutter())


@pytest.mark.parametrize("origin", [[46.8, 8.2, 0.0], ["46.8", "8.2"], [True, False], [46.8]])
def test_recipe_origin_not_two_numbers_is_an_input_error(
        tmp_path: Path, states: dict[str, Any], origin: list[Any]) -> None:
    """A radars' origin of three values raised a plain ``ValueError`` at the rebuild
    ('too many values to unpack'); strings or booleans were taken as degrees."""
    members, _ = states["async"]
    meta = _meta(members)
    meta["recipe"]["sensors"]["origin"] = origin
    path = write_members(tmp_path / "s.npz", _with_meta(members, meta))
    with pytest.raises(InputError) as e:
        build.load_tracker(path)
    assert str(e.value).startswith(f"{path}, member 'meta': field 'recipe.sensors.origin'")
    assert e.value.file == str(path) and e.value.key == "meta"


def test_recipe_that_cannot_be_rebuilt_is_an_input_error(
        tmp_path: Path, states: dict[str, Any], monkeypatch: pytest.MonkeyPatch) -> None:
    """Whatever the checks let through and the rebuild refuses is an InputError naming
    the file and the member (before: a plain ValueError)."""
    members, _ = states["async"]
    path = write_members(tmp_path / "s.npz", members)

    def refuse(*args: Any, **kwargs: Any) -> None:
        raise ValueError("refused")

    monkeypatch.setattr(build.parts, "make_tracker", refuse)
    with pytest.raises(InputError, match=r"member 'meta': field 'recipe' cannot be rebuilt "
                                         r"\(refused\)") as e:
        build.load_tracker(path)
    assert e.value.file == str(path) and e.value.key == "meta"


def _config_fields() -> list[tuple[str, Any]]:
    from dataclasses import fields

    from mhtrack.mht.config import MHTConfig

    return [(f.name, f.default) for f in fields(MHTConfig)
            if isinstance(f.default, int | float) and not isinstance(f.default, bool)]


@pytest.mark.parametrize(("name", "default"), _config_fields(),
                         ids=[n for n, _ in _config_fields()])
def test_config_by_hand_is_bounded(name: str, default: Any) -> None:
    """``MHTConfig`` made by hand in Python: every number beyond :mod:`mhtrack.bounds`
    (a float beyond ±1e15 or not finite, an integer beyond ±2^53) raises ``ValueError``
    naming the field; before, ``sigma_w=1e308`` or ``max_leaves=10**30`` were taken and
    overflowed later, inside ``step``."""
    from mhtrack.mht.config import MHTConfig

    huge = 10**30 if isinstance(default, int) else 1e308
    for value in (huge, -huge) + (() if isinstance(default, int) else (math.inf, math.nan)):
        with pytest.raises(ValueError, match=rf"^MHTConfig\.{name}"):
            MHTConfig(**{name: value})
    MHTConfig(**{name: default})  # the default itself is within every bound


def test_config_bound_message() -> None:
    from mhtrack.mht.config import MHTConfig

    with pytest.raises(ValueError) as e:
        MHTConfig(sigma_w=1e308)
    assert str(e.value) == ("MHTConfig.sigma_w: 1e+308 is out of range (expected a finite "
                            "number in [-1e15, 1e15])")
