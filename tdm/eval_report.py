"""What ``tdm evaluate`` writes and prints: metrics.json (rounded, sorted, null for NaN) and the terminal table."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

#: Significant digits kept for floats in metrics.json.
SIGNIFICANT_DIGITS = 6
#: Keys whose floats keep more digits (latitude/longitude: 6 significant digits would be ~10 m).
FULL_PRECISION_KEYS = frozenset({"frame_origin_lat_lon_deg"})
FULL_PRECISION_DIGITS = 12


def _clean(value, digits: int = SIGNIFICANT_DIGITS):
    """JSON-ready copy: numpy scalars to Python, floats to ``digits`` significant digits, NaN/inf to None.

    Keys in :data:`FULL_PRECISION_KEYS` keep 12 significant digits (geodetic coordinates).
    """
    if isinstance(value, dict):
        return {str(k): _clean(v, FULL_PRECISION_DIGITS if k in FULL_PRECISION_KEYS else digits)
                for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v, digits) for v in value]
    if isinstance(value, np.ndarray):
        return [_clean(v, digits) for v in value.tolist()]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        x = float(value)
        if not math.isfinite(x):
            return None
        return float(f"{x:.{digits}g}")
    return value


def write_metrics(recording: Path, metrics: dict) -> Path:
    """Write ``RECORDING/tdm/metrics.json`` atomically (temporary name, then rename); returns its path.

    Keys are sorted, floats rounded to 6 significant digits, NaN written as null.
    """
    out = Path(recording) / "tdm" / "metrics.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(json.dumps(_clean(metrics), sort_keys=True, indent=1, allow_nan=False) + "\n",
                       encoding="utf-8")
        os.replace(tmp, out)
    finally:
        if tmp.exists():
            tmp.unlink()
    return out


def _fmt(value, digits: int = 2) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


#: Rows of the terminal table: (label, key, digits).
_TABLE_ROWS = (
    ("OSPA [m]", "ospa_m", 2),
    ("GOSPA [m]", "gospa_m", 2),
    ("GOSPA c = 10 m, within LiDAR range [m]", "gospa_within_lidar_range_c10_m", 2),
    ("position RMSE [m]", "position_rmse_m", 2),
    ("median position error [m]", "median_position_error_m", 2),
    ("  within LiDAR range [m]", "median_position_error_within_lidar_range_m", 2),
    ("  beyond LiDAR range [m]", "median_position_error_beyond_lidar_range_m", 2),
    ("COG RMSE [deg]", "cog_rmse_deg", 2),
    ("SOG RMSE [m/s]", "sog_rmse_mps", 3),
    ("detection rate", "detection_rate", 3),
    ("max detection latency [s]", "detection_latency_max_s", 1),
    ("  from first in range [s]", "detection_latency_from_first_in_range_max_s", 1),
    ("false targets / min", "false_targets_per_min", 2),
    ("false reports / min", "false_reports_per_min", 2),
    ("targets on land", "targets_on_land", 0),
    ("ID switches", "id_switches", 0),
    ("NEES mean (ideal 2)", "nees", 2),
    ("NEES in 95 % interval", "nees_fraction_in_95", 3),
    ("classification accuracy", "classification_accuracy", 3),
)


def format_table(metrics: dict) -> str:
    """A short readable table of the metrics for the terminal.

    Parameters
    ----------
    metrics : dict
        What :func:`evaluate` returns (or metrics.json loaded).

    Returns
    -------
    str
        The fused metrics with one column per sensor, then one line per truth object.
    """
    params = metrics.get("parameters", {})
    sensors = sorted(metrics.get("per_sensor") or {})
    columns = [("fused", metrics)] + [(s, metrics["per_sensor"][s]) for s in sensors]
    label_w = max(len(label) for label, _, _ in _TABLE_ROWS) + 2
    lines = [f"TDM evaluation: c = {_fmt(params.get('c_m'), 0)} m, p = {_fmt(params.get('p'), 0)}, "
             f"{metrics.get('epochs')} epochs, {_fmt(params.get('duration_s'), 1)} s, "
             f"sensors {', '.join(params.get('sensors_rendered') or []) or 'none'}",
             "metric".ljust(label_w) + "".join(name.rjust(9) for name, _ in columns)]
    for label, key, digits in _TABLE_ROWS:
        lines.append(label.ljust(label_w) + "".join(_fmt(m.get(key), digits).rjust(9) for _, m in columns))
    versus = (metrics.get("fusion_against_sensors") or {}).get("summary")
    if versus and versus.get("objects_compared"):
        lines.append(f"fusion beats its best sensor on all six figures (position, COG, SOG; RMSE and median): "
                     f"{versus['objects_fusion_beats_best_on_all']} of {versus['objects_compared']} objects "
                     f"seen by two or more sensors")
    objects = metrics.get("per_object") or []
    if objects:
        name_w = max(12, max(len(o["name"]) for o in objects) + 2)
        lines.append("")
        lines.append("object".ljust(name_w) + "kind".ljust(10) + "latency_s".rjust(10) + "matched".rjust(9)
                     + "switches".rjust(9) + "median_err_m".rjust(13))
        for o in objects:
            lines.append(o["name"].ljust(name_w) + str(o["kind"]).ljust(10) + _fmt(o["latency_s"], 1).rjust(10)
                         + _fmt(o["matched_fraction"], 2).rjust(9) + _fmt(o["id_switches"]).rjust(9)
                         + _fmt(o["median_error_m"], 2).rjust(13))
    return "\n".join(lines)

