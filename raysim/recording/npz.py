"""Deterministic .npz files: numpy's own format, zip entries stamped 1980-01-01.

``numpy.savez`` stamps each zip entry with the current time, so identical data
would give different bytes; this writer fixes the stamp (same seed, same bytes)
and writes atomically.
"""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np

from groundfloor.recording import SweepSchema, sweep_file_name
from raysim.recording.staging import atomic_path

_EPOCH = (1980, 1, 1, 0, 0, 0)


def write_npz(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write ``arrays`` (name -> array, in the given order) as an uncompressed .npz file."""
    with atomic_path(Path(path)) as tmp, zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_STORED) as archive:
        for name, array in arrays.items():
            buffer = io.BytesIO()
            np.lib.format.write_array(buffer, np.ascontiguousarray(array), allow_pickle=False)
            info = zipfile.ZipInfo(f"{name}.npy", date_time=_EPOCH)
            info.external_attr = 0o644 << 16
            archive.writestr(info, buffer.getvalue())


def write_sweep(sweeps_dir: Path, number: int, schema: SweepSchema, arrays: dict[str, np.ndarray]) -> None:
    """Write sweep ``number`` as ``sweeps_dir/NNNNNN.npz``, its arrays held to the recording contract.

    The names, dtypes and dimensions are :mod:`groundfloor.recording`'s (``schema.conform``: a
    breach is a ``ValueError``, a writer's bug), the contract the TDM's readers check by.
    """
    write_npz(Path(sweeps_dir) / sweep_file_name(number), schema.conform(arrays))
