"""The values ``tdm evaluate`` takes from manifest.json and scenario.yaml, checked.

Each is a finite number in its range or the file and key path are named in a
:class:`tdm.errors.RecordingError`: a rate, range or duration in a file never sizes an
allocation unchecked (the epoch grid is bounded in :mod:`tdm.eval_truth`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from tdm.errors import RecordingError

#: Default TDM output rate when the scenario gives none, Hz (the default of ``tdm.update_rate_hz``, docs/scenario.md).
DEFAULT_UPDATE_RATE_HZ = 1.0
#: Highest output rate the evaluation accepts, Hz (truth is sampled at 10 Hz).
MAX_UPDATE_RATE_HZ = 1000.0
#: LiDAR range when the scenario gives none, m (docs/reference.md section 2: HDL-32E returns to 100 m).
DEFAULT_LIDAR_RANGE_M = 100.0
#: Sensors whose in-range region the evaluation knows.
SENSORS = ("lidar", "radar", "ais")


@dataclass(frozen=True)
class EvalParams:
    """What the evaluation uses from the manifest and the scenario.

    Attributes
    ----------
    rate_hz : float
        ``tdm.update_rate_hz``, Hz.
    rendered : list of str
        Sensors of :data:`SENSORS` that were rendered and are enabled.
    radar_range_m, ais_range_m, lidar_range_m : float
        ``sensors.radar.range_m``, ``sensors.ais.range_m`` (inf when absent: no limit) and
        ``sensors.lidar.range_max_m`` (default 100 m), metres.
    duration_s : float or None
        The manifest's ``duration_s``, s; None when absent or 0 (the truth's span stands in).
    """

    rate_hz: float
    rendered: list
    radar_range_m: float
    ais_range_m: float
    lidar_range_m: float
    duration_s: float | None


def positive_number(value, default: float, file: Path, where: str, hi: float = math.inf) -> float:
    """A finite number in (0, hi] (``default`` when ``value`` is None); anything else names its key path."""
    if value is None:
        return float(default)
    x = float(value) if type(value) in (int, float) and abs(value) < 1e300 else math.nan
    if not (0.0 < x <= hi and math.isfinite(x)):
        bound = "" if hi == math.inf else f" up to {hi:g}"
        raise RecordingError(str(file), where, f"{_short(value)} is not a finite positive number{bound}")
    return x


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _sensor_config(scenario: dict, sensor: str) -> dict:
    value = scenario.get("sensors", {}).get(sensor)
    return value if isinstance(value, dict) else {}


def _rendered(manifest: dict, scenario: dict, manifest_path: Path) -> list[str]:
    """Sensors of :data:`SENSORS` rendered (manifest ``sensors_rendered``; else enabled in the scenario) and enabled."""
    if "sensors_rendered" in manifest:
        listed = manifest["sensors_rendered"] or []
        if not isinstance(listed, list) or not all(isinstance(s, str) for s in listed):
            raise RecordingError(str(manifest_path), "sensors_rendered",
                                 f"{_short(listed)} is not a list of sensor names")
        names = set(listed)
    else:
        names = {s for s in SENSORS if _sensor_config(scenario, s) and _sensor_config(scenario, s).get("enabled", True)}
    return [s for s in SENSORS if s in names and _sensor_config(scenario, s).get("enabled", True) is not False]


def read_params(recording: Path, manifest: dict, scenario: dict) -> EvalParams:
    """The checked values (:class:`EvalParams`) from the recording's manifest and (resolved) scenario.

    Raises
    ------
    RecordingError
        The manifest not a mapping; ``sensors_rendered`` not a list of names; ``duration_s`` not a
        finite positive number (0 and null allowed: absent); scenario ``sensors`` not a mapping;
        ``tdm.update_rate_hz`` not in (0, 1000] Hz; a range not finite and positive.
    """
    manifest_path, scenario_path = Path(recording) / "manifest.json", Path(recording) / "scenario.yaml"
    if not isinstance(manifest, dict):
        raise RecordingError(str(manifest_path), "(top level)", "must be a mapping")
    sensors = scenario.get("sensors")
    if not isinstance(sensors, dict):
        if sensors is not None:
            raise RecordingError(str(scenario_path), "sensors", "must be a mapping")
        scenario = {**scenario, "sensors": {}}
    tdm_config = scenario.get("tdm") if isinstance(scenario.get("tdm"), dict) else {}
    rate_hz = positive_number(tdm_config.get("update_rate_hz"), DEFAULT_UPDATE_RATE_HZ, scenario_path,
                              "tdm.update_rate_hz", hi=MAX_UPDATE_RATE_HZ)

    def sensor_range(sensor: str, key: str, default: float) -> float:
        value = _sensor_config(scenario, sensor).get(key)
        return default if value is None else positive_number(value, default, scenario_path, f"sensors.{sensor}.{key}")

    duration = manifest.get("duration_s")
    duration_s = None if duration is None or (type(duration) in (int, float) and duration == 0) else \
        positive_number(duration, 0.0, manifest_path, "duration_s")
    return EvalParams(rate_hz=rate_hz, rendered=_rendered(manifest, scenario, manifest_path),
                      radar_range_m=sensor_range("radar", "range_m", math.inf),
                      ais_range_m=sensor_range("ais", "range_m", math.inf),
                      lidar_range_m=sensor_range("lidar", "range_max_m", DEFAULT_LIDAR_RANGE_M),
                      duration_s=duration_s)
