"""The tracker state loader: a valid state restores (and continues bit for bit, checked in
tests/mht); a hostile one — any member replaced, NaN, negative or asymmetric covariances,
wrong shapes, bad JSON, truncated or flipped bytes, a compressed member that expands
beyond the bound, a header that lies about its size — raises
:class:`~mhtrack.errors.InputError` naming the file and the member, never another
exception."""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from npz_members import members as read_members  # tests/helpers
from npz_members import write_members

from mhtrack.clutter.known import KnownClutter
from mhtrack.errors import InputError
from mhtrack.io.npzfile import read_npz
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.records import Scan

FUZZ = settings(derandomize=True, deadline=None, max_examples=100, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])


def _scans(n: int) -> list[Scan]:
    rng = np.random.default_rng(4)
    out = []
    for k in range(n):
        z = np.vstack(([100.0 * k, 50.0 * k], [-80.0 * k, 300.0], rng.uniform(-2e3, 2e3,
                                                                             (5, 2))))
        n_z = len(z)
        out.append(Scan(k, float(k), z + rng.normal(0, 10, z.shape), np.zeros(n_z, np.int64),
                        np.arange(7 * k, 7 * k + n_z)))
    return out


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> dict[str, np.ndarray]:
    """The members of a state saved after a few scans (leaves, history, IMM-free)."""
    trk = MHTTracker(MHTConfig(), KnownClutter(1e-8))
    trk.run(_scans(6))
    path = tmp_path_factory.mktemp("state") / "state.npz"
    trk.save(path)
    return read_members(path)


def _write(path: Path, arrays: dict[str, np.ndarray]) -> Path:
    return write_members(path, arrays, allow_pickle=True)


def _load(path: Path) -> None:
    try:
        MHTTracker.load(path)
    except InputError as e:
        assert str(e).startswith(str(path)), str(e)
        assert "\n" not in str(e)


def test_valid_state_loads(tmp_path: Path, saved: dict[str, np.ndarray]) -> None:
    trk = MHTTracker.load(_write(tmp_path / "s.npz", saved))
    assert len(trk._leaves) == len(saved["leaves__score"]) > 0


@pytest.mark.parametrize(("member", "change", "message"), [
    ("leaves__P", lambda a: np.where(np.eye(4, dtype=bool), -a, a),
     "member 'leaves__P': matrix 0 is not positive definite"),
    ("leaves__P", lambda a: a + np.triu(np.ones((4, 4)), 1),
     "member 'leaves__P': matrix 0 is not symmetric"),
    ("leaves__x", lambda a: np.where(np.arange(a.size).reshape(a.shape) == 1, np.nan, a),
     "member 'leaves__x': value nan at index (0, 1) is not finite"),
    ("leaves__x", lambda a: a[:, :3], "member 'leaves__x': has shape"),
    ("leaves__score", lambda a: a[:-1], "member 'leaves__score': has shape"),
    ("leaves__tree", lambda a: a.astype(np.float64), "member 'leaves__tree': has dtype float64"),
    ("leaves__tree", lambda a: a[::-1].copy() + 0 * a, "leaves are not sorted by tree"),
    ("leaves__track", lambda a: a + 10**6, "member 'leaves__track': ids must be in"),
    ("leaves__window", lambda a: a[:, :2], "member 'leaves__window': has shape"),
    ("leaves__chosen", lambda a: np.array(["x"] * len(a)), "has dtype <U1"),
    ("history__count", lambda a: a + 5, "member 'history__"),
])
def test_hostile_member_is_named(tmp_path: Path, saved: dict[str, np.ndarray], member: str,
                                 change: Any, message: str) -> None:
    members = dict(saved)
    members[member] = change(members[member])
    if "sorted" in message and np.all(members[member][1:] >= members[member][:-1]):
        pytest.skip("one tree only")
    path = _write(tmp_path / "s.npz", members)
    with pytest.raises(InputError) as info:
        MHTTracker.load(path)
    assert str(info.value).startswith(f"{path}, member"), str(info.value)
    assert message in str(info.value)


@pytest.mark.parametrize(("meta", "message"), [
    ("[]", "member 'meta': expected a JSON object, got list"),
    ("{", "member 'meta': not JSON"),
    ('{"format": "other"}', "not an MHT tracker state"),
    (None, "next_tree"),
    ("x", "next_track"),
])
def test_hostile_meta_is_named(tmp_path: Path, saved: dict[str, np.ndarray],
                               meta: str | None, message: str) -> None:
    members = dict(saved)
    if meta is None:
        m = json.loads(str(saved["meta"]))
        m["next_tree"] = 1e20
        meta = json.dumps(m)
    elif meta == "x":
        m = json.loads(str(saved["meta"]))
        m["next_track"] = None
        meta = json.dumps(m)
    members["meta"] = np.array(meta)
    path = _write(tmp_path / "s.npz", members)
    with pytest.raises(InputError, match="member 'meta'") as info:
        MHTTracker.load(path)
    assert message in str(info.value)


def test_bad_config_in_meta_is_named(tmp_path: Path, saved: dict[str, np.ndarray]) -> None:
    m = json.loads(str(saved["meta"]))
    m["config"]["n_scan"] = -3
    path = _write(tmp_path / "s.npz", {**saved, "meta": np.array(json.dumps(m))})
    with pytest.raises(InputError, match=r"member 'meta': cannot be restored"):
        MHTTracker.load(path)


def test_object_arrays_are_refused(tmp_path: Path, saved: dict[str, np.ndarray]) -> None:
    members = {**saved, "leaves__x": np.array([None, 1], dtype=object)}
    path = tmp_path / "s.npz"
    with open(path, "wb") as fh:
        np.savez(fh, **members)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"member 'leaves__x': dtype object is not allowed"):
        MHTTracker.load(path)


def test_member_expanding_beyond_the_bound_is_refused_before_reading(tmp_path: Path) -> None:
    """A compressed member of 64 MiB of zeros (a 64 kB file): refused from the zip
    directory's size, with a bound of 1 MiB (the real bound is 1 GiB)."""
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        buf = io.BytesIO()
        np.lib.format.write_array(buf, np.zeros(8 << 20))
        zf.writestr("meta.npy", buf.getvalue())
    assert path.stat().st_size < 1 << 20
    with pytest.raises(InputError, match=r"member 'meta': expands to 67108992 bytes, more "
                       r"than the 1048576 allowed"):
        read_npz(path, max_member=1 << 20)


def test_header_lying_about_its_shape_is_refused_before_allocating(tmp_path: Path) -> None:
    """A .npy header declaring 10^12 floats over 8 bytes of data: refused from the header,
    nothing allocated."""
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buf, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)})
    buf.write(b"\0" * 8)
    path = tmp_path / "lie.npz"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("leaves__x.npy", buf.getvalue())
    with pytest.raises(InputError, match=r"member 'leaves__x': header says shape "
                       r"\(1000000000000,\)"):
        read_npz(path)


def test_not_a_zip_and_a_fifo_are_one_line(tmp_path: Path) -> None:
    p = tmp_path / "s.npz"
    p.write_bytes(b"PK\x03\x04 not really")
    with pytest.raises(InputError, match=r"s.npz: not a .npz archive"):
        MHTTracker.load(p)
    fifo = tmp_path / "f.npz"
    import os

    os.mkfifo(fifo)
    with pytest.raises(InputError, match=r"f.npz: is a FIFO \(named pipe\), not a regular"):
        MHTTracker.load(fifo)


@FUZZ
@given(cut=st.integers(0, 10**6), flips=st.lists(st.tuples(st.integers(0, 10**6),
                                                             st.integers(1, 255)), max_size=4))
def test_truncated_or_flipped_bytes_load_or_raise_input_error(
        tmp_path: Path, saved: dict[str, np.ndarray], cut: int,
        flips: list[tuple[int, int]]) -> None:
    data = bytearray(_write(tmp_path / "ok.npz", saved).read_bytes())
    for pos, x in flips:
        data[pos % len(data)] ^= x
    path = tmp_path / "bad.npz"
    path.write_bytes(bytes(data[: len(data) - cut % (len(data) + 1)] if cut % 3 == 0
                           else data))
    _load(path)


def _full(shape: tuple[int, ...], v: float, dtype: Any) -> np.ndarray:
    with np.errstate(invalid="ignore", over="ignore"):
        return np.full(shape, v).astype(dtype, copy=False)


arrays = st.one_of(
    st.builds(_full,
              st.lists(st.integers(0, 4), max_size=4).map(tuple),
              st.sampled_from([0, 1, -1, 1e300, np.nan, np.inf, 2**60, 0.5]),
              st.sampled_from([np.float64, np.int64, np.bool_, np.float32, np.uint8, "U3"])),
)


@FUZZ
@given(pick=st.integers(0, 10**6), value=arrays)
def test_any_member_replaced_loads_or_raises_input_error(
        tmp_path: Path, saved: dict[str, np.ndarray], pick: int, value: np.ndarray) -> None:
    names = sorted(saved)
    members = dict(saved)
    members[names[pick % len(names)]] = value
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        path = _write(tmp_path / "m.npz", members)
    _load(path)


def test_header_that_breaks_numpys_parser_is_one_line(tmp_path: Path) -> None:
    """A flipped byte in a header can make NumPy's header parser raise tokenize's
    TokenError (found by the byte-flipping property): still one InputError line."""
    header = b"{'descr': '<f8', 'fortran_order': False, 'shape': (2, 4(, }"
    header += b" " * (63 - len(header) % 64) + b"\n"
    data = b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header + b"\0" * 64
    path = tmp_path / "s.npz"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("leaves__x.npy", data)
    with pytest.raises(InputError, match=r"member 'leaves__x': not a NumPy array"):
        read_npz(path)
