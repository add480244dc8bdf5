"""raysim.recording.npz writes, without building .npy images or concatenating, the bytes numpy and zipfile would."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest

from groundfloor.recording import LIDAR_SWEEP
from raysim.recording import npz


def reference_npz(path, arrays):
    """The writer as it was: numpy.lib.format.write_array into memory, ZipFile.writestr."""
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED) as archive:
        for name, array in arrays.items():
            buffer = io.BytesIO()
            np.lib.format.write_array(buffer, np.ascontiguousarray(array), allow_pickle=False)
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            archive.writestr(info, buffer.getvalue())


ARRAYS = {
    "f32": np.linspace(-1, 1, 1001, dtype=np.float32),
    "u8": np.arange(300, dtype=np.uint8),
    "empty": np.zeros(0, dtype=np.int32),
    "scalar": np.float64(2.5) * np.ones(()),
    "fortran": np.asfortranarray(np.arange(12.0).reshape(3, 4)),
    "strided": np.arange(40, dtype=np.int16)[::3],
    "big_endian": np.arange(5, dtype=">f8"),
    "rows": np.arange(24, dtype=np.uint16).reshape(8, 3),
}


def test_whole_arrays_are_the_reference_bytes(tmp_path):
    npz.write_npz(tmp_path / "new.npz", ARRAYS)
    reference_npz(tmp_path / "old.npz", ARRAYS)
    assert (tmp_path / "new.npz").read_bytes() == (tmp_path / "old.npz").read_bytes()


@pytest.mark.parametrize("cuts", [[0], [0, 3], [0, 0, 5, 5, 7], [0, 8]])
def test_pieces_are_the_bytes_of_their_concatenation(tmp_path, cuts):
    whole = {k: v for k, v in ARRAYS.items() if v.ndim >= 1 and k != "fortran"}
    bounds = lambda n: [min(c, n) for c in cuts] + [n]  # noqa: E731
    pieces = {k: [v[a:b] for a, b in zip(bounds(len(v))[:-1], bounds(len(v))[1:])] for k, v in whole.items()}
    npz.write_npz_pieces(tmp_path / "pieces.npz", pieces)
    reference_npz(tmp_path / "whole.npz", whole)
    assert (tmp_path / "pieces.npz").read_bytes() == (tmp_path / "whole.npz").read_bytes()


def test_sweep_pieces_keep_the_contract(tmp_path):
    good = {"x": [np.zeros(2, np.float32)] * 2, "y": [np.zeros(2, np.float32)] * 2, "z": [np.zeros(2, np.float32)] * 2,
            "intensity": [np.zeros(2, np.uint8)] * 2, "ring": [np.zeros(2, np.uint8)] * 2,
            "time": [np.zeros(2)] * 2, "azimuth_deg": [np.zeros(2, np.float32)] * 2}
    npz.write_sweep_pieces(tmp_path, 3, LIDAR_SWEEP, good)
    with np.load(tmp_path / "000003.npz") as loaded:
        assert loaded["x"].shape == (4,)
    with pytest.raises(ValueError):
        npz.write_sweep_pieces(tmp_path, 4, LIDAR_SWEEP, {**good, "x": [np.zeros(2, np.float64)] * 2})
    with pytest.raises(ValueError):
        npz.write_sweep_pieces(tmp_path, 5, LIDAR_SWEEP, {**good, "x": [np.zeros(2, np.float32), np.zeros(2, np.float64)]})


# ---------------------------------------------------------------------- the one-pass reader


def test_read_npz_gives_what_np_load_gives(tmp_path):
    """Every dtype, shape (empty, scalar, 2-d, big-endian) of this writer's files: the same arrays as np.load."""
    arrays = {**ARRAYS, "grid": np.arange(24, dtype=np.int16).reshape(4, 6), ">f8": np.arange(5, dtype=">f8")}
    npz.write_npz(tmp_path / "a.npz", arrays)
    read = npz.read_npz(tmp_path / "a.npz")
    with np.load(tmp_path / "a.npz") as reference:
        assert list(read) == reference.files
        for name in reference.files:
            assert read[name].dtype == reference[name].dtype and read[name].shape == reference[name].shape
            assert np.array_equal(read[name], reference[name])


def test_read_npz_of_other_writers_falls_back_to_np_load(tmp_path, monkeypatch):
    """A compressed .npz (numpy's savez_compressed) is not parsed here but read by np.load, to the same arrays."""
    np.savez_compressed(tmp_path / "c.npz", x=np.arange(100.0), y=np.ones((3, 3), dtype=np.uint8))
    assert npz._parse_stored((tmp_path / "c.npz").read_bytes()) is None
    read = npz.read_npz(tmp_path / "c.npz")
    assert np.array_equal(read["x"], np.arange(100.0)) and read["y"].shape == (3, 3)
    # and a member whose header says more data than it holds is not trusted either
    npz.write_npz(tmp_path / "s.npz", {"x": np.arange(10.0)})
    data = bytearray((tmp_path / "s.npz").read_bytes())
    at = data.index(b"(10,)")
    data[at:at + 5] = b"(11,)"
    assert npz._parse_stored(bytes(data)) is None
