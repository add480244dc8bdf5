"""Detected-target messages (thesis Table 6.3; docs/contracts.md recording directory) and their files.

One line of ``tdm/detected_targets.jsonl`` per target per output epoch::

    {"t": s since start, "target_id": int, "object_descriptor": "vessel" | "iceberg" |
     "fixed obstacle" | "unknown", "longitude": deg, "latitude": deg, "cog_deg": [0, 360),
     "sog_mps": >= 0, "cross_section_m2": float, "sources": ["ais", "lidar", "radar"],
     "position_cov_m2": [[ee, en], [ne, nn]], "mmsi": int | null}

``tdm/sensor_tracks.jsonl`` holds each sensor's confirmed tracks at the same epochs in the
same form plus ``"sensor"`` (and ``target_id`` is then the sensor's track id).
"""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path
from typing import Iterator

import numpy as np

from tdm import ekf
from tdm.frames import EnuFrame


def target_record(t_s: float, target_id: int, descriptor: str, x: np.ndarray, p: np.ndarray, sources: list[str],
                  frame: EnuFrame, mmsi: int | None = None, sensor: str | None = None,
                  lat_lon_deg: tuple[float, float] | None = None) -> dict:
    """One detected-target line from a state (6,) and covariance (6, 6) in the TDM frame.

    ``lat_lon_deg``: the position's latitude and longitude (degrees) when already converted
    (:func:`target_records`); default: converted here through ``frame``.
    """
    lat, lon = frame.to_geodetic(x[ekf.E], x[ekf.N]) if lat_lon_deg is None else lat_lon_deg
    speed, course = float(x[ekf.U]), float(x[ekf.PSI])
    if speed < 0:  # the model allows a negative speed; report it as motion the other way
        speed, course = -speed, course + np.pi
    (c00, c01), (c10, c11) = p[:2, :2].tolist()
    rec = {"t": round(float(t_s), 6), "target_id": int(target_id), "object_descriptor": descriptor,
           "longitude": round(float(lon), 8), "latitude": round(float(lat), 8),
           "cog_deg": round(float(np.mod(np.degrees(course), 360.0)), 3), "sog_mps": round(speed, 4),
           "cross_section_m2": round(float(x[ekf.ALPHA]), 3), "sources": list(sources),
           "position_cov_m2": [[round(c00, 4), round(c01, 4)], [round(c10, 4), round(c11, 4)]],
           "mmsi": None if mmsi is None else int(mmsi)}
    if sensor is not None:
        rec["sensor"] = sensor
    return rec


def target_records(t_s: float, rows: list[tuple], frame: EnuFrame) -> list[dict]:
    """:func:`target_record` of many states at one time, their positions converted to lat/lon in one call.

    Parameters
    ----------
    t_s : float
        Time of the records, s since the start.
    rows : list of tuple
        ``(target_id, descriptor, x (6,), p (6, 6), sources, mmsi, sensor)`` per record (``mmsi``, ``sensor``
        may be None).
    frame : EnuFrame
    """
    if not rows:
        return []
    east = np.array([row[2][ekf.E] for row in rows])
    north = np.array([row[2][ekf.N] for row in rows])
    lat, lon = frame.to_geodetic(east, north)
    return [target_record(t_s, target_id, descriptor, x, p, sources, frame, mmsi, sensor, lat_lon_deg=(la, lo))
            for (target_id, descriptor, x, p, sources, mmsi, sensor), la, lo in zip(rows, lat.tolist(), lon.tolist())]


#: The encoder of every line (``json.dumps(record, separators=(", ", ": "))``, made once).
_ENCODER = json.JSONEncoder(separators=(", ", ": "))


@contextlib.contextmanager
def jsonl_writer(path: Path) -> Iterator:
    """Write JSON lines to a temporary sibling and rename it to ``path`` on success (atomic)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        with open(tmp, "w", encoding="utf-8") as handle:
            def write(record: dict) -> None:
                handle.write(_ENCODER.encode(record) + "\n")
            yield write
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
