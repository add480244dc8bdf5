"""Validated, streaming reads of the JSON-lines files that ``tdm evaluate`` scores.

The files are read one line at a time (never a list of dicts for a whole file): each line must
be a JSON mapping whose fields have the right types, numbers finite, times in order. Anything
else is a :class:`tdm.errors.RecordingError` naming the file, the line and the field (``tdm
evaluate`` prints it as one line and exits 2). What is kept goes into compact columns
(``array.array``, then numpy).

Also here: :func:`read_reports` (``tdm/detected_targets.jsonl``, ``tdm/sensor_tracks.jsonl``).
"""

from __future__ import annotations

import json
import math
from array import array
from pathlib import Path
from typing import Iterator

import numpy as np

from tdm.errors import RecordingError
from tdm.frames import EnuFrame

#: A field value is shown in an error message up to this many characters.
SHOWN_CHARS = 40
#: Marker of an absent field.
ABSENT = object()


def _shown(value) -> str:
    """A short one-line rendering of a JSON value for an error message."""
    text = json.dumps(value)  # NaN and infinities as JSON's extension writes them: NaN, Infinity
    return text if len(text) <= SHOWN_CHARS else text[:SHOWN_CHARS - 3] + "..."


class LineReader:
    """The non-blank lines of a JSON-lines file as mappings, with field checks naming the line.

    Parameters
    ----------
    path : Path
        The file; a missing file is a RecordingError ``missing``.
    """

    def __init__(self, path: Path):
        self.path = Path(path)
        self.number = 0

    def fail(self, what: str, where: str | None = None) -> RecordingError:
        """A RecordingError at the current line (or at ``where``)."""
        return RecordingError(str(self.path), where or f"line {self.number}", what)

    def rows(self) -> Iterator[dict]:
        """Each non-blank line parsed; sets :attr:`number` to its (1-based) line number."""
        try:
            handle = open(self.path, "rb")  # decoded line by line: a bad byte is reported at its line
        except FileNotFoundError:
            raise RecordingError(str(self.path), "(file)", "missing") from None
        except OSError as exc:
            raise RecordingError(str(self.path), "(file)", f"cannot be read ({exc.strerror})") from None
        with handle:
            self.number = 0
            for raw in handle:  # loop over lines
                self.number += 1
                try:
                    line = raw.decode("utf-8")
                except UnicodeDecodeError as exc:
                    raise self.fail(f"not UTF-8 text (byte 0x{raw[exc.start]:02x})") from None
                if line.isspace():
                    continue
                try:
                    row = json.loads(line)
                except json.JSONDecodeError as exc:
                    raise self.fail(f"not valid JSON: {exc.msg}") from None
                except RecursionError:
                    raise self.fail("not valid JSON: nested too deeply") from None
                if not isinstance(row, dict):
                    raise self.fail(f"not a JSON object (a mapping): {_shown(row)}")
                yield row

    def number_field(self, row: dict, key: str, default=ABSENT, null=False, lo: float = -math.inf,
                     hi: float = math.inf) -> float:
        """A finite number in [lo, hi]; ``default`` when absent (required without one); NaN for null if ``null``."""
        value = row.get(key, ABSENT)
        kind = type(value)
        if kind is float or kind is int:
            x = float(value) if kind is float or abs(value) < 2 ** 1000 else math.inf
            if lo <= x <= hi and x - x == 0.0:  # x - x: NaN for NaN and infinities
                return x
            bounds = "" if lo == -math.inf and hi == math.inf else f" in [{lo:g}, {hi:g}]"
            raise self.fail(f"field {key!r}: {_shown(value)} is not a finite number{bounds}")
        if value is ABSENT:
            if default is ABSENT:
                raise self.fail(f"field {key!r} missing")
            return default
        if value is None and null:
            return math.nan
        raise self.fail(f"field {key!r}: {_shown(value)} is not a number")

    def int_field(self, row: dict, key: str) -> int:
        """A required JSON integer (not a bool, not a float), within int64."""
        value = row.get(key, ABSENT)
        if type(value) is int and -2 ** 63 <= value < 2 ** 63:
            return value
        if value is ABSENT:
            raise self.fail(f"field {key!r} missing")
        raise self.fail(f"field {key!r}: {_shown(value)} is not an integer")

    def str_field(self, row: dict, key: str, default=ABSENT) -> str:
        """A string; ``default`` when absent or null (required without one)."""
        value = row.get(key, ABSENT)
        if type(value) is str:
            return value
        if value is ABSENT or value is None:
            if default is ABSENT:
                raise self.fail(f"field {key!r} missing" if value is ABSENT else f"field {key!r} is null")
            return default
        raise self.fail(f"field {key!r}: {_shown(value)} is not a string")

    def bool_field(self, row: dict, key: str) -> bool:
        """``true``/``false``; absent or null is False."""
        value = row.get(key)
        if value is None or value is True or value is False:
            return bool(value)
        raise self.fail(f"field {key!r}: {_shown(value)} is not true or false")

    def cov_field(self, row: dict, key: str) -> tuple[float, float, float, float] | None:
        """A 2 x 2 matrix of finite numbers ``[[a, b], [c, d]]`` as (a, b, c, d); None when absent or null."""
        value = row.get(key)
        if value is None:
            return None
        if type(value) is list and len(value) == 2 and all(type(r) is list and len(r) == 2 for r in value):
            flat = (value[0][0], value[0][1], value[1][0], value[1][1])
            if all(type(x) in (int, float) and abs(x) < 1e300 for x in flat):  # NaN and inf fail abs() < 1e300
                return tuple(float(x) for x in flat)
        raise self.fail(f"field {key!r}: {_shown(value)} is not a 2x2 matrix of finite numbers")

    def in_order(self, t_s: float, previous_s: float) -> float:
        """``t_s``, checked not to be before ``previous_s`` (the file's times must not go back)."""
        if t_s < previous_s:
            raise self.fail(f"field 't': {t_s!r} is before the previous line's {previous_s!r} (times must be in order)")
        return t_s


#: Latitude and longitude bounds, degrees.
LAT_BOUND_DEG, LON_BOUND_DEG = 90.0, 180.0
#: Times (s since the recording's start) are accepted in [0, MAX_TIME_S] (about three years): the epoch grid
#: is computed from them.
MAX_TIME_S = 1e8


def read_reports(path: Path, frame: EnuFrame, with_sensor: bool = False) -> dict[str, np.ndarray]:
    """detected_targets.jsonl (or sensor_tracks.jsonl) as columns in the frame ``frame``, read line by line.

    :func:`read_report_columns`, then :func:`reports_in_frame`.

    Each line must be a mapping with ``t`` (s in [0, :data:`MAX_TIME_S`], not before the previous line's), ``target_id``
    (integer), ``latitude`` / ``longitude`` (finite degrees within +-90 / +-180); optional
    ``cog_deg``, ``sog_mps`` (finite number or null), ``object_descriptor`` (string),
    ``position_cov_m2`` (2 x 2 finite numbers or null), and ``sensor`` (string, required when
    ``with_sensor``).

    Parameters
    ----------
    path : Path
        The JSON-lines file.
    frame : EnuFrame
        The evaluation's frame.
    with_sensor : bool
        Also read the ``sensor`` field (sensor_tracks.jsonl).

    Returns
    -------
    dict of arrays
        ``t`` (N,) s, ``target_id`` (N,) int64, ``east_m``, ``north_m`` (N,) m, ``cog_deg``,
        ``sog_mps`` (N,) (NaN when null), ``position_cov_m2`` (N, 2, 2) m^2 (NaN when
        absent), ``descriptor`` (N,) str, and ``sensor`` (N,) str when asked for.

    Raises
    ------
    RecordingError
        The file missing, or a line that is not as above (its number and field named).
    """
    return reports_in_frame(read_report_columns(path, with_sensor), frame)


def reports_in_frame(columns: dict[str, np.ndarray], frame: EnuFrame) -> dict[str, np.ndarray]:
    """:func:`read_report_columns`'s columns with ``latitude``/``longitude`` (N,) deg replaced by
    ``east_m``/``north_m`` (N,) m in ``frame``."""
    out = dict(columns)
    lat, lon = out.pop("latitude"), out.pop("longitude")
    out["east_m"], out["north_m"] = frame.to_enu(lat, lon) if lat.size else (np.zeros(0), np.zeros(0))
    return out


def read_report_columns(path: Path, with_sensor: bool = False) -> dict[str, np.ndarray]:
    """:func:`read_reports` before the frame: ``latitude``, ``longitude`` (N,) deg instead of east and north."""
    reader = LineReader(path)
    cols = {name: array("d") for name in ("t", "lat", "lon", "cog_deg", "sog_mps", "cov")}
    target_id = array("q")
    labels: dict[str, list] = {"descriptor": [], "sensor": []}
    shared: dict[str, str] = {}  # one str object per distinct label
    nan4 = (math.nan,) * 4
    previous_s = -math.inf
    for row in reader.rows():  # loop over lines (JSON parsing is per line)
        previous_s = reader.in_order(reader.number_field(row, "t", lo=0.0, hi=MAX_TIME_S), previous_s)
        cols["t"].append(previous_s)
        target_id.append(reader.int_field(row, "target_id"))
        cols["lat"].append(reader.number_field(row, "latitude", lo=-LAT_BOUND_DEG, hi=LAT_BOUND_DEG))
        cols["lon"].append(reader.number_field(row, "longitude", lo=-LON_BOUND_DEG, hi=LON_BOUND_DEG))
        cols["cog_deg"].append(reader.number_field(row, "cog_deg", default=math.nan, null=True))
        cols["sog_mps"].append(reader.number_field(row, "sog_mps", default=math.nan, null=True))
        cols["cov"].extend(reader.cov_field(row, "position_cov_m2") or nan4)
        descriptor = reader.str_field(row, "object_descriptor", default="unknown")
        labels["descriptor"].append(shared.setdefault(descriptor, descriptor))
        if with_sensor:
            sensor = reader.str_field(row, "sensor")
            labels["sensor"].append(shared.setdefault(sensor, sensor))
    n = len(target_id)
    lat, lon = np.frombuffer(cols["lat"], dtype=float), np.frombuffer(cols["lon"], dtype=float)
    out = {"t": np.frombuffer(cols["t"], dtype=float).copy(), "target_id": np.frombuffer(target_id, dtype=np.int64).copy(),
           "cog_deg": np.frombuffer(cols["cog_deg"], dtype=float).copy(),
           "sog_mps": np.frombuffer(cols["sog_mps"], dtype=float).copy(),
           "descriptor": _object_array(labels["descriptor"])}
    out["latitude"], out["longitude"] = lat.copy(), lon.copy()
    out["position_cov_m2"] = np.frombuffer(cols["cov"], dtype=float).reshape(n, 2, 2).copy()
    if with_sensor:
        out["sensor"] = _object_array(labels["sensor"])
    return out


def _object_array(values: list) -> np.ndarray:
    """(N,) object array of the given Python objects (strings are not turned into a fixed-width dtype)."""
    out = np.empty(len(values), dtype=object)
    out[:] = values
    return out
