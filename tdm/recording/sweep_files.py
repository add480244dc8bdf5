"""The numbered sweep files of a sensor (``<sensor>/sweeps/NNNNNN.npz``) and their order in time.

* :func:`list_sweeps` lists the files named by a number, in the order of the numbers. A number
  missing between the first and the last is a warning (``"<sensor>: sweep files missing from the
  numbering"``, counted per missing number): a logger that dropped a revolution, or a partial copy.
  An entry that is not a readable regular file (a directory, a link loop, no permission) and two
  files with one number (``5.npz`` and ``000005.npz``) are errors.
* :class:`SweepOrder` checks, sweep by sweep, that each starts no earlier than the previous one
  of its sensor ended: files renamed out of order or duplicated are an error naming the file.
  Nothing else can reorder a sensor's revolutions.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.recording.files import file_problem

__all__ = ["list_sweeps", "SweepOrder", "gap_warning", "TIME_MARGIN_S", "sweep_window_s"]

_NUMBERED = re.compile(r"^(\d+)\.npz$")
#: How far before the start and after the end of the run a sweep's times may lie, s (sensor clocks
#: and the last revolution's tail); beyond it a time is not of this run.
TIME_MARGIN_S = 60.0


def gap_warning(sensor: str) -> str:
    """Warning key of missing sweep numbers."""
    return f"{sensor}: sweep files missing from the numbering"


def sweep_window_s(duration_s: float) -> tuple[float, float]:
    """Times (s since the start) a sweep of a run of ``duration_s`` may hold: the run +- :data:`TIME_MARGIN_S`."""
    return -TIME_MARGIN_S, float(duration_s) + TIME_MARGIN_S


def list_sweeps(directory: Path, sensor: str, stats: ReadStats | None = None) -> list[Path]:
    """The numbered sweep files of ``directory`` in number order (module docstring).

    Parameters
    ----------
    directory : Path
        ``<recording>/<sensor>/sweeps``.
    sensor : str
        ``"lidar"`` or ``"radar"`` (names the warnings).
    stats : ReadStats, optional
        Receives the count of missing numbers.

    Returns
    -------
    list of Path
    """
    directory = Path(directory)
    try:
        names = os.listdir(directory)
    except OSError as exc:
        raise RecordingError(str(directory), "(directory)", f"unreadable ({exc.strerror})") from None
    numbered = sorted((int(m.group(1)), name) for name in names if (m := _NUMBERED.match(name)))
    for (a, first), (b, second) in zip(numbered, numbered[1:]):
        if a == b:
            raise RecordingError(str(directory / second), "(file)", f"numbered {a} like {first}: which sweep is it?")
    for _, name in numbered:
        why = file_problem(directory / name)
        if why is not None:
            raise RecordingError(str(directory / name), "(file)", why)
    if numbered and stats is not None:
        missing = numbered[-1][0] - numbered[0][0] + 1 - len(numbered)
        if missing:
            stats.count(gap_warning(sensor), missing)
    return [directory / name for _, name in numbered]


class SweepOrder:
    """The end time of the last sweep of each sensor; a sweep that starts before it is an error."""

    def __init__(self) -> None:
        self._last: dict[str, tuple[float, str]] = {}

    def check(self, sensor: str, path: Path, t_start_s: float, t_end_s: float) -> None:
        """Accept the next sweep of ``sensor`` (times s since the start) or raise RecordingError."""
        previous = self._last.get(sensor)
        if previous is not None and t_start_s < previous[0]:
            raise RecordingError(str(path), "time", f"starts at {t_start_s:.6g} s, before {previous[1]} ends "
                                                    f"({previous[0]:.6g} s): sweeps out of order or duplicated")
        end = t_end_s if previous is None else max(t_end_s, previous[0])
        self._last[sensor] = (end, Path(path).name)
