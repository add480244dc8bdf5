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
                  frame: EnuFrame, mmsi: int | None = None, sensor: str | None = None) -> dict:
    """One detected-target line from a state (6,) and covariance (6, 6) in the TDM frame."""
    lat, lon = frame.to_geodetic(x[ekf.E], x[ekf.N])
    speed, course = float(x[ekf.U]), float(x[ekf.PSI])
    if speed < 0:  # the model allows a negative speed; report it as motion the other way
        speed, course = -speed, course + np.pi
    cov = p[:2, :2]
    rec = {"t": round(float(t_s), 6), "target_id": int(target_id), "object_descriptor": descriptor,
           "longitude": round(float(lon), 8), "latitude": round(float(lat), 8),
           "cog_deg": round(float(np.mod(np.degrees(course), 360.0)), 3), "sog_mps": round(speed, 4),
           "cross_section_m2": round(float(x[ekf.ALPHA]), 3), "sources": list(sources),
           "position_cov_m2": [[round(float(cov[0, 0]), 4), round(float(cov[0, 1]), 4)],
                               [round(float(cov[1, 0]), 4), round(float(cov[1, 1]), 4)]],
           "mmsi": None if mmsi is None else int(mmsi)}
    if sensor is not None:
        rec["sensor"] = sensor
    return rec


@contextlib.contextmanager
def jsonl_writer(path: Path) -> Iterator:
    """Write JSON lines to a temporary sibling and rename it to ``path`` on success (atomic)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        with open(tmp, "w", encoding="utf-8") as handle:
            def write(record: dict) -> None:
                handle.write(json.dumps(record, separators=(", ", ": ")) + "\n")
            yield write
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
