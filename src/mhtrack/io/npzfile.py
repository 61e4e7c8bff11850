"""Reading a NumPy ``.npz`` archive safely: sizes checked from the zip directory and each
member's ``.npy`` header before any array is allocated.

:func:`read_npz` refuses, with one :class:`~mhtrack.errors.InputError` line naming the
file and the member, an archive that is not a zip file, a member that is not a ``.npy``
array, one whose uncompressed size (from the zip directory, which also bounds what
:mod:`zipfile` will inflate) exceeds ``max_member`` bytes or makes the total exceed
``max_total`` (a compressed "zip bomb"), a header whose shape and dtype do not match the
member's size, object (pickled) arrays and dtypes other than booleans, integers, floats
and text. Bounds: :data:`mhtrack.bounds.MAX_STATE_MEMBER_BYTES`,
:data:`~mhtrack.bounds.MAX_STATE_BYTES`.
"""

from __future__ import annotations

import zipfile
import zlib
from os import PathLike

import numpy as np

from mhtrack.bounds import MAX_STATE_BYTES, MAX_STATE_MEMBER_BYTES, clip
from mhtrack.errors import InputError
from mhtrack.io.paths import check_input_file

#: dtype kinds a member may hold: bool, signed and unsigned integers, floats, text.
KINDS = "biufU"
#: What a damaged archive raises while a member is read (bad CRC or header, corrupt
#: deflate stream, unsupported compression or encryption, truncated data).
_DAMAGED = (zipfile.BadZipFile, zlib.error, NotImplementedError, RuntimeError, EOFError,
            OSError, ValueError)


def member_error(path: str | PathLike[str], member: str | None, problem: str) -> InputError:
    """``<file>, member '<name>': <problem>`` (without the member when ``None``)."""
    where = f"{path}" + (f", member {clip(member, 60)!r}" if member is not None else "")
    return InputError(f"{where}: {problem}", file=str(path), key=member)


def _header(zf: zipfile.ZipFile, info: zipfile.ZipInfo, path: str | PathLike[str],
            name: str) -> None:
    """Check the ``.npy`` header of ``info`` against its size, without reading the data."""
    fmt = np.lib.format
    try:
        fh = zf.open(info)
    except _DAMAGED as e:
        raise member_error(path, name, f"damaged ({clip(str(e), 120)})") from None
    with fh:
        try:
            version = fmt.read_magic(fh)
            if version == (1, 0):
                shape, _fortran, dtype = fmt.read_array_header_1_0(fh)
            elif version in ((2, 0), (3, 0)):
                shape, _fortran, dtype = fmt.read_array_header_2_0(fh)
            else:
                raise ValueError(f"unknown .npy version {version}")
            offset = fh.tell()
        except Exception as e:  # a hostile header can make NumPy's parser
            # (ast, tokenize) raise anything; every such failure is the same user error
            raise member_error(path, name, f"not a NumPy array ({clip(str(e), 120)})") from None
    if dtype.hasobject or dtype.kind not in KINDS or dtype.fields is not None:
        raise member_error(path, name, f"dtype {dtype} is not allowed (expected booleans, "
                           "integers, floats or text; never Python objects)")
    count = 1
    for n in shape:
        count *= int(n)
    if count * dtype.itemsize != info.file_size - offset:
        raise member_error(path, name, f"header says shape {tuple(shape)} of {dtype} "
                           f"({count * dtype.itemsize} bytes) but the member holds "
                           f"{info.file_size - offset} bytes of data")


def read_npz(path: str | PathLike[str], *, max_member: int = MAX_STATE_MEMBER_BYTES,
             max_total: int = MAX_STATE_BYTES) -> dict[str, np.ndarray]:
    """The arrays of the ``.npz`` file ``path`` by name (module docstring for the checks).

    Raises
    ------
    InputError : one line naming the file and, when about one, the member.
    """
    check_input_file(path)
    try:
        zf = zipfile.ZipFile(path)
    except _DAMAGED as e:
        raise member_error(path, None, f"not a .npz archive ({clip(str(e), 120)})") from None
    with zf:
        total = 0
        names = []
        for info in zf.infolist():
            name = info.filename.removesuffix(".npy")
            if not info.filename.endswith(".npy") or info.is_dir():
                raise member_error(path, info.filename, "not a .npy array member")
            if info.file_size > max_member:
                raise member_error(path, name, f"expands to {info.file_size} bytes, more "
                                   f"than the {max_member} allowed for one member")
            total += info.file_size
            if total > max_total:
                raise member_error(path, name, f"the members expand to more than "
                                   f"{max_total} bytes in all (the limit)")
            _header(zf, info, path, name)
            names.append((name, info))
        out = {}
        for name, info in names:
            try:
                with zf.open(info) as fh:
                    out[name] = np.lib.format.read_array(fh, allow_pickle=False)
            except _DAMAGED as e:
                raise member_error(path, name, f"cannot be read ({clip(str(e), 120)})") from None
    return out
