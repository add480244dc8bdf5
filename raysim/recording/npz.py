"""Deterministic .npz files: numpy's own format, zip entries stamped 1980-01-01.

``numpy.savez`` stamps each zip entry with the current time, so identical data
would give different bytes; this writer fixes the stamp (same seed, same bytes)
and writes atomically.

The arrays' bytes go from their own memory into the archive: no ``.npy`` image is
built in memory first, and an array given in pieces (a LiDAR revolution gathered
from two chunks) is written piece after piece, never concatenated. The zip records
are :func:`groundfloor.zip_stored.stored_archive`'s, written front to back (zipfile
writes each member's header twice, seeking back for its CRC: a sweep file took 92
writes). The file is the one ``numpy.lib.format.write_array`` and ``ZipFile.writestr``
would give (``tests/raysim/test_npz_pieces.py`` holds the two to it).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from groundfloor.recording import SweepSchema, sweep_file_name
from groundfloor.npy_header import NPY_PREFIX_BYTES, numpy_header_text
from groundfloor.zip_stored import stored_archive, stored_members
from raysim.recording.staging import atomic_path

_EPOCH = (1980, 1, 1, 0, 0, 0)
#: The members' Unix mode (rw-r--r--), in the zip entries' external attributes.
_MODE = 0o644 << 16


def npy_header(dtype: np.dtype, shape: tuple[int, ...]) -> bytes:
    """The ``.npy`` header (format 1.0, C order) of an array of this dtype and shape."""
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buffer, {"descr": np.lib.format.dtype_to_descr(np.dtype(dtype)), "fortran_order": False, "shape": tuple(shape)})
    return buffer.getvalue()


def write_npz_pieces(path: Path, pieces: Mapping[str, Sequence[np.ndarray]]) -> None:
    """Write arrays given in pieces as an uncompressed .npz file, each the pieces' concatenation.

    Parameters
    ----------
    path : Path
        The file (written under a temporary name and renamed).
    pieces : mapping of str to sequence of ndarray
        Name -> one or more arrays of one dtype, equal in every dimension but the first
        (concatenated along it), in the order the members are written.
    """
    members = []
    for name, parts in pieces.items():
        parts = [np.ascontiguousarray(p) for p in parts]  # (at least 1-d, as write_npz always wrote)
        shape = (sum(p.shape[0] for p in parts),) + parts[0].shape[1:]
        members.append((f"{name}.npy", [npy_header(parts[0].dtype, shape)]
                        + [memoryview(p).cast("B") for p in parts if p.nbytes]))
    buffers = stored_archive(members, _EPOCH, _MODE)
    with atomic_path(Path(path)) as tmp, open(tmp, "wb") as handle:
        for buffer in buffers:
            handle.write(buffer)


def write_npz(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write ``arrays`` (name -> array, in the given order) as an uncompressed .npz file."""
    write_npz_pieces(path, {name: [array] for name, array in arrays.items()})


def write_sweep(sweeps_dir: Path, number: int, schema: SweepSchema, arrays: dict[str, np.ndarray]) -> None:
    """Write sweep ``number`` as ``sweeps_dir/NNNNNN.npz``, its arrays held to the recording contract.

    The names, dtypes and dimensions are :mod:`groundfloor.recording`'s (``schema.conform``: a
    breach is a ``ValueError``, a writer's bug), the contract the TDM's readers check by.
    """
    write_npz(Path(sweeps_dir) / sweep_file_name(number), schema.conform(arrays))


def write_sweep_pieces(sweeps_dir: Path, number: int, schema: SweepSchema,
                       pieces: Mapping[str, Sequence[np.ndarray]]) -> None:
    """:func:`write_sweep` of arrays given in pieces (:func:`write_npz_pieces`), never concatenated.

    Each array's first piece is held to the contract (all pieces share its dtype and dimensions).
    """
    for name, parts in pieces.items():
        if any(p.dtype != parts[0].dtype or p.shape[1:] != parts[0].shape[1:] for p in parts):
            raise ValueError(f"{schema.sensor} sweep: the pieces of {name} differ in dtype or shape")
    schema.conform({name: parts[0] for name, parts in pieces.items()})
    write_npz_pieces(Path(sweeps_dir) / sweep_file_name(number), pieces)


_NPY_MAGIC = b"\x93NUMPY\x01\x00"


def read_npz(path: Path) -> dict[str, np.ndarray]:
    """Every array of an .npz file, read in one pass: views on the file's bytes, no copies.

    The files this module writes (stored members, ``.npy`` format 1.0, C order) are parsed here
    directly (the zip directory by :func:`groundfloor.zip_stored.stored_members`, which the TDM's
    reader uses too): ``np.load`` spends most of a small sweep's read on zipfile's machinery, a CRC of
    every member and a Python parse of every header. Any other file (compressed, another writer's, a
    header this parser does not know) is read with ``np.load``. For files this run wrote (the bag, the
    pictures): the CRCs are not checked; the TDM's reader checks them.
    """
    data = Path(path).read_bytes()
    arrays = _parse_stored(data)
    if arrays is None:
        with np.load(io.BytesIO(data)) as archive:
            arrays = {name: archive[name] for name in archive.files}
    return arrays


def _parse_stored(data: bytes) -> dict[str, np.ndarray] | None:
    """The members of a stored .npz image as arrays, or None where anything is not as this writer writes it."""
    members = stored_members(data)
    if not members:
        return None
    arrays: dict[str, np.ndarray] = {}
    for member in members:
        array = _parse_npy(data, member.data_start, member.file_size) if member.filename.endswith(".npy") else None
        if array is None:
            return None
        arrays[member.filename[:-4]] = array
    return arrays


def _parse_npy(data: bytes, start: int, length: int) -> np.ndarray | None:
    """An ``.npy`` format 1.0 image at ``data[start:start + length]`` as a read-only view, or None."""
    if data[start:start + 8] != _NPY_MAGIC:
        return None
    offset = start + NPY_PREFIX_BYTES + int.from_bytes(data[start + 8:start + NPY_PREFIX_BYTES], "little")
    decoded = numpy_header_text(data, start + NPY_PREFIX_BYTES, offset)
    if decoded is None or decoded[1]:  # another text, or Fortran order: np.load's
        return None
    shape, _, dtype = decoded
    count = int(np.prod(shape, dtype=np.int64))
    if offset + count * dtype.itemsize != start + length:
        return None
    return np.frombuffer(data, dtype=dtype, count=count, offset=offset).reshape(shape)
