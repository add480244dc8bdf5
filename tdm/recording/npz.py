"""NumPy ``.npz`` archives read without trusting them: headers first, then bounded loads.

``np.load`` allocates what an array's header claims before it reads a byte, and fails with
``BadZipFile``, ``EOFError``, ``ValueError`` or ``zlib.error`` on a cut or damaged file. Here:

* :func:`read_layout` opens the zip directory and reads each ``<name>.npy`` member's header only:
  dtype, shape, order. A header whose size (shape x item size) is not the size the zip directory
  gives for the member, or beyond :data:`MAX_ARRAY_BYTES`, is refused before anything is allocated.
* :func:`load_arrays` then reads the asked members into arrays of exactly that checked size.

A file of up to :data:`IN_MEMORY_MAX_BYTES` is read in one system call. When it is a plain archive of
stored (uncompressed) members, which is how ``np.savez`` and raysim write sweeps, its directory is read
from those bytes (:mod:`groundfloor.zip_stored`) and each member's data sliced out of them, its
CRC-32 checked as ``zipfile`` checks it; any other archive (compressed, damaged, larger) is read by
``zipfile``, which also says what is wrong with a damaged one. Each ``.npy`` header is read by a fast
parser of numpy's own header text (anything else goes to numpy's parser). Both routes give the same
arrays and the same errors (tests/tdm/test_recording.py).

A file that cannot be read as such an archive at all (zero bytes, not a zip, cut short, damaged
member data or header) raises :class:`Unreadable` with a short reason: what copying or a crash
leaves, which callers count as a warning. A path that is not a readable regular file raises
:class:`tdm.errors.RecordingError` (:func:`tdm.recording.files.regular_file`). Object (pickled)
arrays raise :class:`tdm.errors.RecordingError`: a sweep holds numbers only.
"""

from __future__ import annotations

import functools
import io
import math
import os
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tdm.errors import RecordingError
from tdm.recording.files import regular_file
from groundfloor.npy_header import NPY_PREFIX_BYTES, numpy_header_text
from groundfloor.zip_stored import StoredMember, stored_members

__all__ = ["ArrayHeader", "NpzFile", "Unreadable", "read_layout", "load_arrays", "MAX_ARRAY_BYTES",
           "IN_MEMORY_MAX_BYTES"]

#: Largest array accepted in a sweep file, bytes (a radar sweep's echo is 2 MiB, a LiDAR sweep's x 0.3 MiB).
MAX_ARRAY_BYTES = 1 << 30
#: Longest ``.npy`` header text accepted, bytes (numpy writes 128 and refuses to read over 10,000).
MAX_HEADER_BYTES = 1 << 16
#: Files up to this size are read whole, in one system call (a radar sweep is 2 MiB, a LiDAR sweep 0.6 MiB).
IN_MEMORY_MAX_BYTES = 1 << 28
_ZIP_ERRORS = (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, NotImplementedError, RuntimeError,
               KeyError)


class Unreadable(Exception):
    """A file that cannot be read as an archive of ``.npy`` arrays.

    Attributes
    ----------
    reason : str
        How, one fixed phrase (:data:`ZERO_BYTES`, :data:`NOT_A_ZIP`, :data:`CUT_SHORT`, :data:`DAMAGED`): the
        warning keys of the callers are built from it.
    detail : str
        Which array and what was found, for a reader of the message.
    """

    def __init__(self, reason: str, detail: str = ""):
        self.reason, self.detail = reason, detail
        super().__init__(f"{reason}: {detail}" if detail else reason)

    def __reduce__(self):
        return (type(self), (self.reason, self.detail))


ZERO_BYTES = "zero bytes"
NOT_A_ZIP = "not a zip archive"
CUT_SHORT = "zip archive cut short"
DAMAGED = "damaged array data"


@dataclass(frozen=True)
class ArrayHeader:
    """What a member's ``.npy`` header says.

    Attributes
    ----------
    name : str
        Array name (member name without ``.npy``).
    dtype : numpy.dtype
    shape : tuple of int
    fortran_order : bool
    """

    name: str
    dtype: np.dtype
    shape: tuple[int, ...]
    fortran_order: bool

    @property
    def nbytes(self) -> int:
        return math.prod(self.shape) * self.dtype.itemsize


def _open_zip(path: Path) -> tuple[zipfile.ZipFile | None, bytes | None, list[StoredMember] | None]:
    """The archive: a :class:`zipfile.ZipFile` (None when the members were found without it), the file's
    bytes when it is small enough to be read whole (else None), and its stored members when it is a
    plain archive of them (:func:`groundfloor.zip_stored.stored_members`; else None)."""
    regular_file(path)
    size = os.stat(path).st_size
    if size == 0:
        raise Unreadable(ZERO_BYTES)
    with open(path, "rb") as handle:
        data = handle.read() if size <= IN_MEMORY_MAX_BYTES else None
        magic = data[:2] if data is not None else handle.read(2)
    if magic != b"PK":
        raise Unreadable(NOT_A_ZIP)
    members = stored_members(data) if data is not None else None
    if members is not None:
        return None, data, members
    try:
        return zipfile.ZipFile(io.BytesIO(data) if data is not None else path), data, None
    except _ZIP_ERRORS:
        raise Unreadable(CUT_SHORT) from None


@functools.lru_cache(maxsize=512)
def _decode_header(raw: bytes) -> tuple[tuple[int, ...], bool, np.dtype] | tuple[int, int]:
    """(shape, fortran order, dtype) of a ``.npy`` header's bytes (magic to the end of the header text),
    or the format version when it is neither 1.0 nor 2.0. Cached: the arrays of a sweep, and of the
    sweeps of a run, repeat the same few headers."""
    if raw[:7] == b"\x93NUMPY\x01":
        decoded = numpy_header_text(raw, NPY_PREFIX_BYTES, len(raw))
        if decoded is not None:
            return decoded
    fp = io.BytesIO(raw)
    version = np.lib.format.read_magic(fp)
    if version == (1, 0):
        return np.lib.format.read_array_header_1_0(fp)
    if version == (2, 0):
        return np.lib.format.read_array_header_2_0(fp)
    return version


def _read_exactly(fp, n: int) -> bytes:
    data = fp.read(n)
    if len(data) != n:
        raise EOFError("member ends inside its .npy header")
    return data


def _parse_header(fp, info: zipfile.ZipInfo | StoredMember, path: Path) -> ArrayHeader:
    """The header of a member opened at its start (``fp`` is left at the array's data)."""
    prefix = _read_exactly(fp, 10)  # magic (6), version (2), header length (2 in version 1.0, else 4)
    if prefix[6] != 1:
        prefix += _read_exactly(fp, 2)
    length = _header_length(prefix, info)
    return _checked_header(prefix + _read_exactly(fp, length), info, path)


def _header_length(prefix: bytes, info: zipfile.ZipInfo | StoredMember) -> int:
    """The header text's length, from the 10 or 12 bytes before it (refused beyond :data:`MAX_HEADER_BYTES`)."""
    length = int.from_bytes(prefix[8:], "little")
    if length > MAX_HEADER_BYTES:
        raise Unreadable(DAMAGED, f"array {info.filename[:-4]!r}: a .npy header of {length} bytes")
    return length


def _checked_header(raw: bytes, info: zipfile.ZipInfo | StoredMember, path: Path) -> ArrayHeader:
    """The header ``raw`` (magic to the end of the header text) decoded and checked against the archive."""
    name = info.filename[:-4]
    decoded = _decode_header(raw)
    if len(decoded) == 2:
        raise RecordingError(str(path), name, f".npy format version {decoded} not supported (1.0, 2.0)")
    shape, fortran, dtype = decoded
    if dtype.hasobject:
        raise RecordingError(str(path), name, "holds Python objects (pickled data), not numbers")
    header = ArrayHeader(name, dtype, tuple(int(n) for n in shape), bool(fortran))
    data_offset = len(raw)
    if data_offset + header.nbytes != info.file_size:  # the header and the zip directory disagree
        raise Unreadable(DAMAGED, f"array {name!r}: its header says {header.nbytes} bytes of data, the archive "
                                  f"holds {info.file_size - data_offset}")
    if header.nbytes > MAX_ARRAY_BYTES:  # consistent, but no sweep is that big
        raise RecordingError(str(path), name, f"shape {header.shape} of {header.nbytes} bytes, more than the "
                                              f"{MAX_ARRAY_BYTES} an array of a sweep may hold")
    return header


def _stored_member(data: bytes, info: StoredMember, path: Path, load: bool) -> tuple[ArrayHeader, np.ndarray | None]:
    """A stored member's header, and its array when ``load`` (its CRC-32 checked first, as
    :func:`_read_member` does), sliced from the archive's bytes: what :func:`_member_header` and
    :func:`_read_member` give, without a stream over the member."""
    start, end = info.data_start, info.data_start + info.file_size
    try:
        if load and zlib.crc32(memoryview(data)[start:end]) != info.CRC:
            raise zipfile.BadZipFile(f"bad CRC-32 for {info.filename}")
        prefix = data[start:min(start + 12, end)]
        head = 10 if len(prefix) >= 10 and prefix[6] == 1 else 12
        if len(prefix) < head:
            raise EOFError("member ends inside its .npy header")
        length = _header_length(prefix[:head], info)
        if start + head + length > end:
            raise EOFError("member ends inside its .npy header")
    except _ZIP_ERRORS:
        raise Unreadable(DAMAGED, f"array {info.filename[:-4]!r}") from None
    header = _checked_header(data[start:start + head + length], info, path)
    if not load:
        return header, None
    flat = np.frombuffer(data, dtype=header.dtype, count=math.prod(header.shape), offset=start + head + length).copy()
    if header.fortran_order:
        return header, flat.reshape(header.shape[::-1]).transpose()
    return header, flat.reshape(header.shape)


def _member_header(zf: zipfile.ZipFile | None, info: zipfile.ZipInfo | StoredMember, path: Path,
                   data: bytes | None) -> ArrayHeader:
    try:
        with _member_stream(zf, info, data, check_crc=False) as fp:  # the data is not read: as zipfile, no CRC
            return _parse_header(fp, info, path)
    except _ZIP_ERRORS:
        raise Unreadable(DAMAGED, f"array {info.filename[:-4]!r}") from None


def _member_stream(zf: zipfile.ZipFile | None, info: zipfile.ZipInfo | StoredMember, data: bytes | None,
                   check_crc: bool = True):
    """A stream over a member's data: from the bytes in memory for a member of a plain stored archive
    (:class:`StoredMember`; its CRC-32 checked unless ``check_crc`` is false), else
    :meth:`zipfile.ZipFile.open` (which checks it at the end)."""
    if not isinstance(info, StoredMember):
        return zf.open(info)
    member = memoryview(data)[info.data_start:info.data_start + info.file_size]
    if check_crc and zlib.crc32(member) != info.CRC:
        raise zipfile.BadZipFile(f"bad CRC-32 for {info.filename}")
    return _MemberView(member)


class _MemberView:
    """A read-only stream over a member's bytes in memory (``read``, ``readinto``), without copying them."""

    def __init__(self, view: memoryview):
        self._view, self._at = view, 0

    def read(self, n: int = -1) -> bytes:
        end = len(self._view) if n < 0 else min(self._at + n, len(self._view))
        chunk = bytes(self._view[self._at:end])
        self._at = end
        return chunk

    def readinto(self, buffer: memoryview) -> int:
        n = min(len(buffer), len(self._view) - self._at)
        buffer[:n] = self._view[self._at:self._at + n]
        self._at += n
        return n

    def __enter__(self) -> "_MemberView":
        return self

    def __exit__(self, *exc) -> None:
        self._view.release()


class NpzFile:
    """An open ``.npz`` archive: ``layout`` (every array's checked header) and :meth:`load`.

    Use as a context manager. Opening raises as :func:`read_layout`.

    Parameters
    ----------
    path : Path
    preload : tuple of str
        Arrays to read while the headers are read (one pass over each member); :meth:`load` then
        hands them out.
    """

    def __init__(self, path: Path, preload: tuple[str, ...] = ()):
        self.path = Path(path)
        self._zf, self._data, members = _open_zip(self.path)
        self._loaded: dict[str, np.ndarray] = {}
        try:
            infos = members if members is not None else self._zf.infolist()
            self._infos = {info.filename[:-4]: info for info in infos if info.filename.endswith(".npy")}
            self.layout = {}
            for name, info in self._infos.items():
                if members is not None:  # a plain stored archive in memory
                    self.layout[name], array = _stored_member(self._data, info, self.path, name in preload)
                    if array is not None:
                        self._loaded[name] = array
                elif name in preload:
                    self.layout[name], self._loaded[name] = _read_member(self._zf, info, self.path, self._data)
                else:
                    self.layout[name] = _member_header(self._zf, info, self.path, self._data)
        except BaseException:
            self.close()
            raise

    def load(self, names: tuple[str, ...]) -> dict[str, np.ndarray]:
        """The arrays ``names`` as ``np.load`` would give them (dtype, shape and order of the file)."""
        missing = [n for n in names if n not in self._infos]
        if missing:
            raise RecordingError(str(self.path), missing[0], "array missing")
        return {n: self._loaded[n] if n in self._loaded
                else _read_member(self._zf, self._infos[n], self.path, self._data)[1] for n in names}

    def close(self) -> None:
        if self._zf is not None:
            self._zf.close()
        self._data = None

    def __enter__(self) -> "NpzFile":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def read_layout(path: Path) -> dict[str, ArrayHeader]:
    """Every array's header of an ``.npz`` file, checked against the zip directory (module docstring).

    Raises
    ------
    Unreadable
        Zero bytes, not a zip, cut short, or a damaged member.
    RecordingError
        Not a readable regular file; an object array; an array beyond :data:`MAX_ARRAY_BYTES`.
    """
    with NpzFile(path) as npz:
        return npz.layout


def _read_member(zf: zipfile.ZipFile | None, info: zipfile.ZipInfo | StoredMember, path: Path,
                 data: bytes | None = None) -> tuple[ArrayHeader, np.ndarray]:
    try:
        with _member_stream(zf, info, data) as fp:
            header = _parse_header(fp, info, path)
            flat = np.empty(math.prod(header.shape), dtype=header.dtype)  # size checked against the archive
            view = memoryview(flat.view(np.uint8)) if header.nbytes else memoryview(bytearray(0))
            got = 0
            while got < header.nbytes:
                n = fp.readinto(view[got:])
                if not n:
                    raise Unreadable(DAMAGED, f"array {header.name!r} cut short")
                got += n
            fp.read(1)  # reach the member's end: the zip CRC is checked there
    except _ZIP_ERRORS:
        raise Unreadable(DAMAGED, f"array {info.filename[:-4]!r}") from None
    if header.fortran_order:
        return header, flat.reshape(header.shape[::-1]).transpose()
    return header, flat.reshape(header.shape)


def load_arrays(path: Path, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """The arrays ``names`` of an ``.npz`` file (each must be in it; errors as :func:`read_layout`)."""
    with NpzFile(path) as npz:
        return npz.load(names)
