"""LiDAR and radar sweep files (``lidar/sweeps/NNNNNN.npz``, ``radar/sweeps/NNNNNN.npz``) against their contract.

A sweep's arrays are described by :class:`SweepSchema` (the recording contract,
:mod:`groundfloor.recording`, which raysim's writers follow too; docs/formats.md): each array's name, dtype
(either byte order) and axes; arrays sharing an axis must agree on its length (LiDAR: one entry
per point; radar: ``echo`` is spokes x samples, ``azimuth_deg``, ``heading_deg`` and ``time`` one
per spoke, ``range_m`` one per sample, ``object_id`` and ``object_spokes`` one per object).
Required arrays must be there; optional ones (truth and extensions) are checked when present;
arrays the contract does not name are ignored (a newer writer may add some).

:func:`check_layout` checks that from the headers alone (nothing loaded); :func:`check_values`
checks the loaded arrays: finite floats, ``time`` within the run's window, LiDAR rings 0..31, radar
video levels 0..15, ``range_m`` ascending from >= 0, counts >= 0. :func:`read_sweep` does both.
Each breach raises :class:`tdm.errors.RecordingError` ``<file>: <array>: <what>``; a file that is not
a readable archive at all raises :class:`tdm.recording.npz.Unreadable`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from groundfloor.recording import LIDAR_SWEEP, RADAR_SWEEP, SCHEMAS, ArraySpec, SweepSchema
from tdm.errors import RecordingError
from tdm.recording.npz import ArrayHeader, NpzFile

__all__ = ["ArraySpec", "SweepSchema", "LIDAR_SWEEP", "RADAR_SWEEP", "SCHEMAS", "check_layout", "check_values",
           "read_sweep", "read_sweep_layout", "unreadable_warning"]


def unreadable_warning(sensor: str, reason: str) -> str:
    """Warning key of a sweep file that is not a readable archive (:class:`tdm.recording.npz.Unreadable` reason)."""
    return f"{sensor}/sweeps: unreadable sweep files ({reason})"


def check_layout(path: Path, layout: dict[str, ArrayHeader], schema: SweepSchema,
                 expected: dict[str, int] | None = None) -> dict[str, int]:
    """Check a sweep file's array headers against its schema.

    Parameters
    ----------
    path : Path
        Named in errors.
    layout : dict of str to ArrayHeader
        :func:`tdm.recording.npz.read_layout` of the file.
    schema : SweepSchema
    expected : dict of str to int, optional
        Axis lengths the recording's scenario.yaml states (radar ``spokes``, ``samples``).

    Returns
    -------
    dict of str to int
        Length of each axis (``points``; or ``spokes``, ``samples``, ``objects``).
    """
    sizes: dict[str, tuple[int, str]] = {}
    for spec in schema.arrays:
        header = layout.get(spec.name)
        if header is None:
            if spec.required:
                raise RecordingError(str(path), spec.name, "array missing")
            continue
        if header.dtype.newbyteorder("=") != np.dtype(spec.dtype):
            raise RecordingError(str(path), spec.name, f"dtype {header.dtype}, the format says {spec.dtype}")
        if len(header.shape) != len(spec.axes):
            raise RecordingError(str(path), spec.name, f"shape {header.shape}: the format says {len(spec.axes)} "
                                                       f"dimension(s), [{', '.join(spec.axes)}]")
        for axis, n in zip(spec.axes, header.shape):
            if axis in sizes and sizes[axis][0] != n:
                raise RecordingError(str(path), spec.name, f"{n} {axis}, but {sizes[axis][1]} has {sizes[axis][0]}")
            sizes.setdefault(axis, (n, spec.name))
    for axis, n in (expected or {}).items():
        if axis in sizes and sizes[axis][0] != n:
            size, name = sizes[axis]
            raise RecordingError(str(path), name, f"{size} {axis}, but scenario.yaml sensors.{schema.sensor}.{axis} "
                                                  f"says {n}")
    return {axis: size for axis, (size, _) in sizes.items()}


def _first_bad(path: Path, name: str, array: np.ndarray, bad: np.ndarray, what: str) -> None:
    if bad.any():
        index = np.unravel_index(int(np.argmax(bad)), array.shape)
        place = index[0] if len(index) == 1 else tuple(int(i) for i in index)
        value = array[index].item()
        raise RecordingError(str(path), name, f"{what} at index {place} ({value:.6g})" if isinstance(value, float)
                             else f"{what} at index {place} ({value!r})")


def check_values(path: Path, arrays: dict[str, np.ndarray], schema: SweepSchema,
                 window_s: tuple[float, float]) -> None:
    """Check the loaded arrays' values (module docstring).

    Parameters
    ----------
    path : Path
        Named in errors.
    arrays : dict of str to ndarray
        Some or all of the file's arrays, as loaded.
    schema : SweepSchema
    window_s : (float, float)
        Earliest and latest time a sweep of this run may hold, s since the start.
    """
    for name, array in arrays.items():
        spec = schema.spec(name)
        if spec is None or array.size == 0 or _plainly_good(name, array, spec, window_s):
            continue
        if array.dtype.kind == "f":
            _first_bad(path, name, array, ~np.isfinite(array), "not a finite number")
        if spec.low is not None:
            _first_bad(path, name, array, array < spec.low, f"below {spec.low:g}")
        if spec.high is not None:
            _first_bad(path, name, array, array > spec.high, f"above {spec.high:g}")
        if spec.ascending and array.size > 1:
            _first_bad(path, name, array[1:], np.diff(array) <= 0, "not ascending")
        if name == "time":
            low, high = window_s
            _first_bad(path, name, array, (array < low) | (array > high),
                       f"outside the run ({low:g} s to {high:g} s)")


def _plainly_good(name: str, array: np.ndarray, spec: ArraySpec, window_s: tuple[float, float]) -> bool:
    """Whether an array passes every check of :func:`check_values` but ``ascending``, from its least and
    greatest value alone (two reductions instead of a mask per check; NaN makes both NaN, and any
    comparison with NaN false). False means only "look closer": the checks then run one by one, in
    their order, and name the first bad value."""
    if spec.ascending:
        return False
    low, high = array.min(), array.max()
    bounds = [spec.low if spec.low is not None else -np.inf, spec.high if spec.high is not None else np.inf]
    if name == "time":
        bounds = [max(bounds[0], window_s[0]), min(bounds[1], window_s[1])]
    if array.dtype.kind == "f" and not (np.isfinite(low) and np.isfinite(high)):
        return False
    return bool(bounds[0] <= low and high <= bounds[1])


def read_sweep_layout(path: Path, schema: SweepSchema, expected: dict[str, int] | None = None) -> dict[str, int]:
    """Open a sweep file and check its layout only (no array loaded); returns the axis lengths."""
    with NpzFile(path) as npz:
        return check_layout(path, npz.layout, schema, expected)


def read_sweep(path: Path, schema: SweepSchema, fields: tuple[str, ...], window_s: tuple[float, float],
               expected: dict[str, int] | None = None) -> dict[str, np.ndarray]:
    """Load the arrays ``fields`` of a sweep file after checking its layout, then check their values.

    Returns
    -------
    dict of str to ndarray
        The arrays as in the file (see the schema for dtypes and shapes).

    Raises
    ------
    tdm.recording.npz.Unreadable
        Not a readable archive (counted as a warning by the callers).
    RecordingError
        Not a regular file, or the contract is broken (module docstring).
    """
    with NpzFile(path, preload=fields) as npz:
        check_layout(path, npz.layout, schema, expected)
        arrays = npz.load(fields)
    check_values(path, arrays, schema, window_s)
    return arrays
