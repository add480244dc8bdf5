"""Own-ship trajectory files: CSV with ``t_s, lat, lon, heading_deg[, roll_deg, pitch_deg, heave_m]``.

A header line naming the columns is required (any order; extra columns are an
error). Times start at 0 or later and increase strictly; angles are degrees in the
marine convention (roll positive starboard down, pitch positive bow up), heave
metres positive up (roll and pitch within 90 deg, heave within 50 m). Consecutive samples
may not be further apart than a vessel sails (:data:`raysim.limits.MAX_SPEED_MPS`, 60 m/s,
plus 1 m of position jitter). Bad content raises :class:`raysim.errors.InputError` naming
the line.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from raysim.errors import InputError
from raysim.input_files import MAX_CSV_FILE_BYTES, file_problem, read_text_file
from raysim.limits import MAX_SPEED_MPS, fastest_step, speed_text

REQUIRED = ("t_s", "lat", "lon", "heading_deg")
OPTIONAL = ("roll_deg", "pitch_deg", "heave_m")


@dataclass(frozen=True)
class TrajectoryTable:
    """Columns of a trajectory CSV, each (K,) float64; optional columns may be None."""

    t_s: np.ndarray
    lat_deg: np.ndarray
    lon_deg: np.ndarray
    heading_deg: np.ndarray
    roll_deg: np.ndarray | None
    pitch_deg: np.ndarray | None
    heave_m: np.ndarray | None
    line: np.ndarray | None = None  # (K,) line number of each sample in the file


def read_trajectory_csv(path: str | Path) -> TrajectoryTable:
    """Read and validate a trajectory CSV (cached per path and modification time).

    Raises
    ------
    InputError
        Naming the file and the line: not a regular file (a FIFO, socket, device or symlink loop
        is refused without blocking), not UTF-8, bad header or values, times not increasing, or
        a step faster than :data:`raysim.limits.MAX_SPEED_MPS`.
    """
    path = Path(path)
    problem = file_problem(path, "trajectory CSV", MAX_CSV_FILE_BYTES)
    if problem is not None:
        raise InputError(str(path), "(file)", problem)
    try:
        stamp = path.stat().st_mtime_ns
    except OSError:
        raise InputError(str(path), "(file)", "file not found") from None
    return _read(str(path), stamp)


def _rows(path: str) -> tuple[list[str], list[int], np.ndarray]:
    """The header's column names, each data row's line number and the (K, columns) values."""
    text = read_text_file(path, path, "(file)", MAX_CSV_FILE_BYTES, kind="trajectory CSV")
    rows = [(i + 1, r) for i, r in enumerate(csv.reader(io.StringIO(text, newline="")))
            if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise InputError(path, "(file)", "file is empty")
    header_line, header = rows[0]
    names = [h.strip() for h in header]
    for name in names:
        if name not in REQUIRED + OPTIONAL:
            raise InputError(path, f"line {header_line}", f"unknown column {name!r} (columns: {', '.join(REQUIRED + OPTIONAL)})")
    for name in REQUIRED:
        if name not in names:
            raise InputError(path, f"line {header_line}", f"missing column {name!r} (a header line is required)")
    if len(set(names)) != len(names):
        raise InputError(path, f"line {header_line}", "a column is named twice")
    if len(rows) < 3:
        raise InputError(path, "(file)", "needs at least two data lines")
    data = np.empty((len(rows) - 1, len(names)))
    for k, (line, row) in enumerate(rows[1:]):
        if len(row) != len(names):
            raise InputError(path, f"line {line}", f"expected {len(names)} values, got {len(row)}")
        for j, cell in enumerate(row):
            try:
                value = float(cell)
            except ValueError:
                raise InputError(path, f"line {line}", f"{names[j]}: not a number: {cell.strip()!r}") from None
            if not math.isfinite(value):
                raise InputError(path, f"line {line}", f"{names[j]}: must be finite, got {cell.strip()}")
            data[k, j] = value
    return names, [line for line, _ in rows[1:]], data


#: Column -> (bound on the absolute value, message): roll and pitch past 90 deg capsize, and heave
#: beyond 50 m is no wave; t_s is checked separately.
BOUNDS = {
    "lat": (90.0, "latitude must be within [-90, 90]"),
    "lon": (180.0, "longitude must be within [-180, 180]"),
    "roll_deg": (90.0, "must be within [-90, 90] deg"),
    "pitch_deg": (90.0, "must be within [-90, 90] deg"),
    "heave_m": (50.0, "must be within [-50, 50] m"),
}


@lru_cache(maxsize=8)
def _read(path: str, _stamp: int) -> TrajectoryTable:
    names, lines, data = _rows(path)
    col = {name: data[:, j] for j, name in enumerate(names)}
    checks = [("t_s", col["t_s"] < 0, "must be >= 0")]
    checks += [(name, np.abs(col[name]) > bound, message) for name, (bound, message) in BOUNDS.items() if name in col]
    for name, bad, message in checks:
        if bad.any():
            raise InputError(path, f"line {lines[int(np.argmax(bad))]}", f"{name}: {message}")
    step = np.diff(col["t_s"])
    if (step <= 0).any():
        raise InputError(path, f"line {lines[int(np.argmax(step <= 0)) + 1]}", "t_s must increase strictly")
    if col["t_s"][0] > 0:
        raise InputError(path, f"line {lines[0]}", f"the first t_s must be 0, got {col['t_s'][0]:g}")
    fast = fastest_step(col["t_s"], col["lat"], col["lon"])
    if fast is not None:
        k, distance_m, dt_s = fast
        raise InputError(path, f"line {lines[k]}", f"lat, lon: {speed_text(distance_m, dt_s)} from line {lines[k - 1]}; "
                                                   f"a vessel does at most {MAX_SPEED_MPS:g} m/s")
    return TrajectoryTable(
        t_s=col["t_s"], lat_deg=col["lat"], lon_deg=col["lon"], heading_deg=col["heading_deg"],
        roll_deg=col.get("roll_deg"), pitch_deg=col.get("pitch_deg"), heave_m=col.get("heave_m"),
        line=np.asarray(lines, dtype=np.int64),
    )
