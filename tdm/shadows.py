"""Which positions lie in the shadow a scan's detections cast from the sensor: there the sensor cannot see, so a
track predicted there missing its detection is no evidence against it (:class:`tdm.tracker.PositionTracker`,
``TrackerConfig.shadow_misses``).

Neither the LiDAR's light nor the radar's microwaves go through an iceberg or a hull: an object behind another, as
the sensor looks, returns nothing while it stays in that shadow. A detection's shadow is the sector of bearings its
extent across the line of sight covers, beyond its range.
"""

from __future__ import annotations

import numpy as np

__all__ = ["across_sight_m", "shadowed"]


def across_sight_m(length_m: np.ndarray, width_m: np.ndarray, orientation_deg: np.ndarray,
                   sight_deg: np.ndarray) -> np.ndarray:
    """(N,) extent across the line of sight of boxes ``length_m`` x ``width_m`` (N,) whose long side lies at
    ``orientation_deg`` (N,) (compass degrees), seen along ``sight_deg`` (N,) (compass degrees from the sensor), m:
    ``L |sin a| + W |cos a|``, ``a`` the angle between the long side and the line of sight; 0 where a size is not
    finite."""
    a = np.radians(np.asarray(orientation_deg, dtype=float) - np.asarray(sight_deg, dtype=float))
    out = np.abs(length_m * np.sin(a)) + np.abs(width_m * np.cos(a))
    return np.where(np.isfinite(out), out, 0.0)


def shadowed(position_m: np.ndarray, own_m: np.ndarray, det_position_m: np.ndarray,
             det_across_m: np.ndarray) -> np.ndarray:
    """(K,) bool: which of ``position_m`` (K, 2) (east, north, m) lie in the shadow of a detection at
    ``det_position_m`` (N, 2) of extent ``det_across_m`` (N,) across the line of sight (:func:`across_sight_m`), seen
    from ``own_m`` (2,): farther from the sensor than the detection and within the bearings its extent covers,
    ``|bearing - bearing_j| <= atan(det_across_m / 2 / range_j)``."""
    position_m = np.asarray(position_m, dtype=float).reshape(-1, 2)
    det_position_m = np.asarray(det_position_m, dtype=float).reshape(-1, 2)
    if position_m.shape[0] == 0 or det_position_m.shape[0] == 0:
        return np.zeros(position_m.shape[0], dtype=bool)
    t = position_m - own_m
    d = det_position_m - own_m
    range_t, range_d = np.hypot(t[:, 0], t[:, 1]), np.hypot(d[:, 0], d[:, 1])
    half_rad = np.arctan2(0.5 * np.asarray(det_across_m, dtype=float), range_d)
    off = np.arctan2(t[:, 0], t[:, 1])[:, None] - np.arctan2(d[:, 0], d[:, 1])[None, :]
    off = (off + np.pi) % (2.0 * np.pi) - np.pi
    behind = (range_t[:, None] > range_d[None, :]) & (np.abs(off) <= half_rad[None, :])
    return behind.any(axis=1)
