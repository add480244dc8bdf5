"""``ownship.jsonl``: the own ship's navigation solution as columns, every value checked.

Each line (:mod:`tdm.recording.jsonl`) must hold every field of :data:`OWNSHIP_FIELDS` as a finite
JSON number (not a string, boolean or null), within :data:`BOUNDS` (``lat`` [-90, 90] and ``lon``
[-180, 360] degrees; angles, heave and speed of a ship); ``t`` strictly increasing from line to line
(the TDM interpolates the pose in time). The file must hold at least one sample. Errors name the line.

For ``tdm run`` and ``tdm info`` the samples must also cover the run (:func:`check_covers_run`): from its start to its
``duration_s`` within :data:`COVER_TOLERANCE_S`. A navigation log that stopped early (a logger killed, a copy cut at a
line's end) would otherwise leave every later scan placed at the last pose, the outputs wrong without a word.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from groundfloor.recording import OWNSHIP
from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.recording import values
from tdm.recording.jsonl import read_jsonl_lines

__all__ = ["read_ownship", "numeric_columns", "check_covers_run", "OWNSHIP_FIELDS", "COVER_TOLERANCE_S"]

OWNSHIP_FIELDS = ("t", "lat", "lon", "x", "y", "z", "heading_deg", "roll_deg", "pitch_deg", "cog_deg", "sog_mps")
#: Bounds of the fields the TDM uses (deg, m, m/s): the format's ranges with room for other conventions.
BOUNDS = {"lat": (-90.0, 90.0), "lon": (-180.0, 360.0), "z": (-1000.0, 1000.0), "heading_deg": (-360.0, 720.0),
          "roll_deg": (-180.0, 180.0), "pitch_deg": (-180.0, 180.0), "cog_deg": (-360.0, 720.0),
          "sog_mps": (-1000.0, 1000.0)}
_MISSING = object()
#: How far the navigation's first and last samples may lie inside the run, s: a sample interval of a 1 Hz log.
COVER_TOLERANCE_S = 1.0


def numeric_columns(rows: list[dict], numbers: list[int], fields: tuple[str, ...], path: Path) -> dict[str, np.ndarray]:
    """The ``fields`` of every row as (N,) float64 columns; a missing, non-numeric or non-finite value is an error.

    Parameters
    ----------
    rows : list of dict
        Parsed lines.
    numbers : list of int
        File line of each row (for the messages).
    fields : tuple of str
    path : Path
        Named in errors.
    """
    out: dict[str, np.ndarray] = {}
    for key in fields:
        col = [row.get(key, _MISSING) for row in rows]
        is_number = [type(v) is float or type(v) is int for v in col]  # bool is not a number here
        if not all(is_number):
            i = is_number.index(False)
            what = "missing" if col[i] is _MISSING else f"must be a number, not {values.describe(col[i])}"
            raise RecordingError(str(path), f"line {numbers[i]}", f"field {key!r} {what}")
        try:
            arr = np.array(col, dtype=np.float64)
        except OverflowError:  # an integer too large for a float
            arr = np.array([float("inf") if abs(v) > 1e308 else v for v in col], dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            i = int(bad[0])
            raise RecordingError(str(path), f"line {numbers[i]}",
                                 f"field {key!r} must be a finite number, not {col[i]!r}")
        out[key] = arr
    return out


def _check_range(columns: dict[str, np.ndarray], numbers: list[int], key: str, low: float, high: float,
                 path: Path) -> None:
    bad = np.flatnonzero((columns[key] < low) | (columns[key] > high))
    if bad.size:
        i = int(bad[0])
        raise RecordingError(str(path), f"line {numbers[i]}",
                             f"field {key!r} = {columns[key][i]:g} is outside [{low:g}, {high:g}]")


def read_ownship(recording: Path, stats: ReadStats | None = None) -> dict[str, np.ndarray]:
    """``ownship.jsonl`` as columns, checked (module docstring).

    Parameters
    ----------
    recording : Path
        The recording directory.
    stats : ReadStats, optional
        Receives the warning of a cut last line (without it such a line is an error).

    Returns
    -------
    dict of str to (N,) float64
        One column per field of :data:`OWNSHIP_FIELDS`: ``t`` s, ``lat``/``lon`` deg, ``x``/``y``/``z`` m,
        angles deg, ``sog_mps`` m/s.
    """
    path = Path(recording) / OWNSHIP
    rows, numbers = read_jsonl_lines(path, stats)
    if not rows:
        raise RecordingError(str(path), "(file)", "holds no navigation samples")
    columns = numeric_columns(rows, numbers, OWNSHIP_FIELDS, path)
    for key, (low, high) in BOUNDS.items():
        _check_range(columns, numbers, key, low, high, path)
    back = np.flatnonzero(np.diff(columns["t"]) <= 0.0)
    if back.size:
        i = int(back[0]) + 1
        raise RecordingError(str(path), f"line {numbers[i]}", f"t = {columns['t'][i]:g} s is not after the "
                                                              f"previous sample's {columns['t'][i - 1]:g} s")
    return columns


def check_covers_run(t_s: np.ndarray, duration_s: float, recording: Path) -> None:
    """A RecordingError (place ``time``) unless the navigation times ``t_s`` (N,) s cover the run ``[0, duration_s]``
    within :data:`COVER_TOLERANCE_S` at either end (module docstring)."""
    first, last = float(t_s[0]), float(t_s[-1])
    if first > COVER_TOLERANCE_S or last < float(duration_s) - COVER_TOLERANCE_S:
        raise RecordingError(str(Path(recording) / OWNSHIP), "time",
                             f"the navigation covers {first:g}-{last:g} s of a {float(duration_s):g} s run: "
                             f"the scans outside it cannot be placed")
