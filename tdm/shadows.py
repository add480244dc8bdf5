"""Which positions lie in the shadow a scan's detections cast from the sensor: there the sensor cannot see, so a
track predicted there missing its detection is no evidence against it (:class:`tdm.tracker.PositionTracker`,
``TrackerConfig.shadow_misses``).

Neither the LiDAR's light nor the radar's microwaves go through an iceberg or a hull: an object behind another, as
the sensor looks, returns nothing while it stays in that shadow. A detection's shadow is the sector of bearings its
extent across the line of sight covers, beyond its far side (its centre plus half its extent along the line of
sight, so that a track just behind its own object's plot is not hidden by it). A detection that holds the sensor
(nearer than half its extent across the line of sight) casts none.
"""

from __future__ import annotations

import numpy as np

__all__ = ["box_extents_m", "shadowed"]


def box_extents_m(length_m: np.ndarray, width_m: np.ndarray, orientation_deg: np.ndarray,
                  sight_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Extents across and along the line of sight of boxes ``length_m`` x ``width_m`` (N,) whose long side lies at
    ``orientation_deg`` (N,) (compass degrees), seen along ``sight_deg`` (N,) (compass degrees from the sensor).

    Returns
    -------
    across_m, along_m : (N,) float
        ``L |sin a| + W |cos a|`` and ``L |cos a| + W |sin a|``, m, ``a`` the angle between the long side and the line
        of sight; where the orientation is not finite, the length both ways (the box's largest extent); 0 where a size
        is not finite.
    """
    length_m, width_m = np.asarray(length_m, dtype=float), np.asarray(width_m, dtype=float)
    a = np.radians(np.asarray(orientation_deg, dtype=float) - np.asarray(sight_deg, dtype=float))
    sin_a, cos_a = np.abs(np.sin(a)), np.abs(np.cos(a))
    across = length_m * sin_a + width_m * cos_a
    along = length_m * cos_a + width_m * sin_a
    unknown = ~np.isfinite(a)
    across, along = np.where(unknown, length_m, across), np.where(unknown, length_m, along)
    return np.where(np.isfinite(across), across, 0.0), np.where(np.isfinite(along), along, 0.0)


def shadowed(position_m: np.ndarray, own_m: np.ndarray, det_position_m: np.ndarray, det_length_m: np.ndarray,
             det_width_m: np.ndarray, det_orientation_deg: np.ndarray) -> np.ndarray:
    """(K,) bool: which of ``position_m`` (K, 2) (east, north, m) lie in the shadow of a detection at
    ``det_position_m`` (N, 2), its box ``det_length_m`` x ``det_width_m`` (N,) m with its long side at
    ``det_orientation_deg`` (N,) (compass degrees), seen from ``own_m`` (2,): farther from the sensor than the
    detection's far side, ``range > range_j + along_j / 2``, and within the bearings its extent covers,
    ``|bearing - bearing_j| <= atan(across_j / 2 / range_j)`` (``across_j``, ``along_j``: :func:`box_extents_m` along
    the line of sight to it); a detection with ``range_j <= across_j / 2`` (the sensor within its extent) casts none."""
    position_m = np.asarray(position_m, dtype=float).reshape(-1, 2)
    d = np.asarray(det_position_m, dtype=float).reshape(-1, 2) - own_m
    sight_rad = np.arctan2(d[:, 0], d[:, 1])
    across, along = box_extents_m(det_length_m, det_width_m, det_orientation_deg, np.degrees(sight_rad))
    range_d = np.hypot(d[:, 0], d[:, 1])
    casts = range_d > 0.5 * across
    if position_m.shape[0] == 0 or not casts.any():
        return np.zeros(position_m.shape[0], dtype=bool)
    t = position_m - own_m
    range_d, sight_rad = range_d[casts], sight_rad[casts]
    far_side = range_d + 0.5 * along[casts]
    half_rad = np.arctan2(0.5 * across[casts], range_d)
    off = np.arctan2(t[:, 0], t[:, 1])[:, None] - sight_rad[None, :]
    off = (off + np.pi) % (2.0 * np.pi) - np.pi
    behind = (np.hypot(t[:, 0], t[:, 1])[:, None] > far_side[None, :]) & (np.abs(off) <= half_rad[None, :])
    return behind.any(axis=1)
