"""Ground truth and navigation as JSON lines, streamed chunk by chunk.

Numbers are written with fixed decimals so that identical inputs give identical
bytes: times 4 decimals (s), lat/lon 9 (deg, 0.1 mm), metres 3, degrees 3, m/s 3.
"""

from __future__ import annotations

import json
from typing import IO, Iterator, Sequence

import numpy as np

from raysim.pose import heading_deg_from_yaw

TRUTH_KEYS = ("t", "id", "name", "kind", "lat", "lon", "x", "y", "centre_lat", "centre_lon", "centre_x", "centre_y",
              "heading_deg", "cog_deg", "sog_mps", "length_m", "beam_m", "height_m", "ais", "mmsi")
OWNSHIP_KEYS = ("t", "lat", "lon", "x", "y", "z", "heading_deg", "roll_deg", "pitch_deg", "cog_deg", "sog_mps")

#: Below this speed the course over ground is undefined; truth reports the heading instead.
COG_MIN_SPEED_MPS = 0.01


def course_and_speed(velocity_mps: np.ndarray, yaw_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Compass COG (deg) and SOG (m/s) from (N, 3) ENU velocities; COG = heading when still."""
    sog = np.hypot(velocity_mps[:, 0], velocity_mps[:, 1])
    cog = np.mod(np.degrees(np.arctan2(velocity_mps[:, 0], velocity_mps[:, 1])), 360.0)
    still = sog < COG_MIN_SPEED_MPS
    cog[still] = heading_deg_from_yaw(yaw_rad[still])
    return cog, sog


def centre_positions_m(position_m: np.ndarray, yaw_rad: np.ndarray, centre_body_m: tuple[float, float]) \
        -> tuple[np.ndarray, np.ndarray]:
    """Local east and north of a body-frame point (the object's centre) at each pose.

    Parameters
    ----------
    position_m : (M, 3) float
        Body origin, local frame (x east, y north), m.
    yaw_rad : (M,) float
        Body x axis from east, counter-clockwise, rad.
    centre_body_m : (x, y) float
        The point in the body frame (x forward, y to port), m.

    Returns
    -------
    x_m, y_m : (M,) float
    """
    cx, cy = centre_body_m
    cos, sin = np.cos(yaw_rad), np.sin(yaw_rad)
    return position_m[:, 0] + cx * cos - cy * sin, position_m[:, 1] + cx * sin + cy * cos


def row_centre_xy(row: dict) -> tuple[float, float]:
    """A truth row's centre (``centre_x``, ``centre_y``), m; its body origin (``x``, ``y``) in a file from before
    truth carried the centre."""
    return row.get("centre_x", row["x"]), row.get("centre_y", row["y"])


def row_centre_lat_lon(row: dict) -> tuple[float, float]:
    """A truth row's centre (``centre_lat``, ``centre_lon``), deg; its body origin in a file from before
    truth carried the centre."""
    return row.get("centre_lat", row["lat"]), row.get("centre_lon", row["lon"])


def _fmt_angle(a: np.ndarray) -> np.ndarray:
    """Round to 3 decimals and fold 360.000 back to 0.000."""
    a = np.round(a, 3)
    a[a >= 360.0] -= 360.0
    return a + 0.0  # no negative zero


def write_truth_chunk(handle: IO[str], t_s: np.ndarray, per_object: Sequence[dict]) -> int:
    """Append truth lines for the times ``t_s`` (M,), time-major, objects in id order.

    Each entry of ``per_object`` holds the static fields (id, name, kind, length_m,
    beam_m, height_m, ais, mmsi) and (M,) arrays lat, lon, x, y (the body origin), centre_lat,
    centre_lon, centre_x, centre_y (the centre of the above-water extents), heading_deg, cog_deg,
    sog_mps. Returns the number of lines written.
    """
    prefixes, columns = [], []
    for o in per_object:
        prefixes.append(f'"id": {o["id"]}, "name": {json.dumps(o["name"])}, "kind": "{o["kind"]}"')
        suffix = (f'"length_m": {o["length_m"]:.2f}, "beam_m": {o["beam_m"]:.2f}, "height_m": {o["height_m"]:.2f}, '
                  f'"ais": {"true" if o["ais"] else "false"}, "mmsi": {o["mmsi"] if o["mmsi"] is not None else "null"}}}')
        columns.append((o["lat"], o["lon"], o["x"], o["y"], o["centre_lat"], o["centre_lon"], o["centre_x"], o["centre_y"],
                        _fmt_angle(o["heading_deg"]), _fmt_angle(o["cog_deg"]), o["sog_mps"], suffix))
    lines = []
    for k, t in enumerate(t_s):
        for prefix, (lat, lon, x, y, clat, clon, cx, cy, hdg, cog, sog, suffix) in zip(prefixes, columns):
            lines.append(
                f'{{"t": {t:.4f}, {prefix}, "lat": {lat[k]:.9f}, "lon": {lon[k]:.9f}, "x": {x[k]:.3f}, "y": {y[k]:.3f}, '
                f'"centre_lat": {clat[k]:.9f}, "centre_lon": {clon[k]:.9f}, "centre_x": {cx[k]:.3f}, "centre_y": {cy[k]:.3f}, '
                f'"heading_deg": {hdg[k]:.3f}, "cog_deg": {cog[k]:.3f}, "sog_mps": {sog[k]:.3f}, {suffix}\n'
            )
    handle.write("".join(lines))
    return len(lines)


def write_ownship_chunk(handle: IO[str], t_s: np.ndarray, c: dict) -> int:
    """Append own-ship navigation lines; ``c`` holds (M,) arrays named as :data:`OWNSHIP_KEYS`."""
    hdg, cog = _fmt_angle(c["heading_deg"]), _fmt_angle(c["cog_deg"])
    lines = [
        f'{{"t": {t:.4f}, "lat": {c["lat"][k]:.9f}, "lon": {c["lon"][k]:.9f}, "x": {c["x"][k]:.3f}, "y": {c["y"][k]:.3f}, '
        f'"z": {c["z"][k]:.3f}, "heading_deg": {hdg[k]:.3f}, "roll_deg": {c["roll_deg"][k]:.3f}, '
        f'"pitch_deg": {c["pitch_deg"][k]:.3f}, "cog_deg": {cog[k]:.3f}, "sog_mps": {c["sog_mps"][k]:.3f}}}\n'
        for k, t in enumerate(t_s)
    ]
    handle.write("".join(lines))
    return len(lines)


def every(period_s: float):
    """Predicate for :func:`truth_epochs`: times that are whole multiples of ``period_s``."""

    def keep(t_s: float) -> bool:
        k = t_s / period_s
        return abs(k - round(k)) < 1e-6

    return keep


def truth_epochs(path, keep) -> "Iterator[tuple[float, list[dict]]]":
    """The rows of a truth.jsonl file, grouped by time, for the times ``keep(t)`` accepts.

    Read line by line (the file is in time order, each line starts with its ``"t"``), so memory
    holds one epoch; only the kept lines are parsed.

    Yields
    ------
    (t_s, rows) : (float, list of dict)
    """
    current, rows, kept = None, [], False
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            t = float(line[6 : line.index(",")])  # '{"t": 12.3000, ...'
            if t != current:
                if rows:
                    yield current, rows
                current, rows, kept = t, [], keep(t)
            if kept:
                rows.append(json.loads(line))
    if rows:
        yield current, rows
