"""Where a radar paints an object's echo: the beam smears it in bearing, its length spreads it in range.

Used by the radar tracker (:class:`tdm.tracker.TrackerConfig` ``echo_hold_beam_deg``): a detection inside a
confirmed track's echo cannot be told from a piece of it.
"""

from __future__ import annotations

import numpy as np

from tdm.ekf import wrap_pi

__all__ = ["inside_echoes"]


def inside_echoes(point_m: np.ndarray, centre_m: np.ndarray, length_m: np.ndarray, own_m: np.ndarray,
                  beam_deg: float, range_margin_m: float) -> np.ndarray:
    """Which points lie inside which echoes, as a radar at ``own_m`` paints them.

    An echo of an object of length L at range R and bearing B, as the beam smears it: bearings within
    ``beam_deg + atan(L / 2 / R)`` of B and ranges within ``L / 2 + range_margin_m`` of R.

    Parameters
    ----------
    point_m : (P, 2) float
        East, north, m.
    centre_m : (C, 2) float
        The echoes' objects' centres, east, north, m.
    length_m : (C,) float
        Their lengths, m (0: a point).
    own_m : (2,) float
        The radar, east, north, m.
    beam_deg, range_margin_m : float

    Returns
    -------
    (P, C) bool
    """
    rel_p = np.asarray(point_m, dtype=float) - own_m
    rel_c = np.asarray(centre_m, dtype=float) - own_m
    range_p, range_c = np.hypot(rel_p[:, 0], rel_p[:, 1]), np.hypot(rel_c[:, 0], rel_c[:, 1])
    bearing_p, bearing_c = np.arctan2(rel_p[:, 0], rel_p[:, 1]), np.arctan2(rel_c[:, 0], rel_c[:, 1])
    half = 0.5 * np.asarray(length_m, dtype=float)
    d_bearing = np.abs(wrap_pi(bearing_p[:, None] - bearing_c[None, :]))
    half_angle = np.radians(beam_deg) + np.arctan2(half, np.maximum(range_c, 1e-9))
    d_range = np.abs(range_p[:, None] - range_c[None, :])
    return (d_bearing <= half_angle[None, :]) & (d_range <= (half + range_margin_m)[None, :])
