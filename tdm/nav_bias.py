"""The own ship's navigation bias in the covariances the TDM reports.

The LiDAR and the radar measure where an object lies from the own ship; the TDM puts it on the chart with the own
ship's navigation solution (ownship.jsonl). A GNSS position error and a compass heading error that change slowly
(a Gauss-Markov bias of minutes: ``sensors.nav.position_bias_m``, 300 s, and ``heading_bias_deg``, 600 s, in
scenario.yaml, docs/scenario.md) are shared by every scan of a track, so filtering does not average them away: a
track's covariance, which assumes each scan's error independent, leaves them out. They are added to what is reported
as a "consider" term (as the Schmidt-Kalman filter treats a bias; :func:`tdm.fusion_rules.consider_covariance`):
the position bias per axis, and the heading bias turning the object about the own ship, across the line of sight,
``(r sigma_psi)^2`` at range r. AIS positions are the other ship's own GNSS fix and carry none of it.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["NAV_RELATIVE_SENSORS", "nav_bias_covariance"]

#: The sensors whose positions are measured from the own ship (and so carry its navigation bias).
NAV_RELATIVE_SENSORS = frozenset({"lidar", "radar"})


def nav_bias_covariance(position_m: np.ndarray, own_m: np.ndarray | None, position_bias_m: float,
                        heading_bias_deg: float) -> np.ndarray:
    """Covariance of the error the own ship's navigation bias puts on positions measured from it.

    Parameters
    ----------
    position_m : (K, 2) or (2,) float
        The positions, east and north, m.
    own_m : (2,) float or None
        The own ship's east and north, m; None or not finite: unknown, the heading term left out.
    position_bias_m : float
        Standard deviation of the GNSS position bias per axis, m.
    heading_bias_deg : float
        Standard deviation of the heading bias, deg.

    Returns
    -------
    (K, 2, 2) or (2, 2) float
        m^2: ``position_bias_m^2 I + (r radians(heading_bias_deg))^2 v v^T``, with r the range from the own ship and
        v the unit vector across the line of sight.
    """
    pos = np.asarray(position_m, dtype=float)
    single = pos.ndim == 1
    pos = pos.reshape(-1, 2)
    out = np.broadcast_to(position_bias_m ** 2 * np.eye(2), (pos.shape[0], 2, 2)).copy()
    if own_m is not None and np.all(np.isfinite(own_m)) and heading_bias_deg > 0.0:
        rel = pos - np.asarray(own_m, dtype=float)[:2]
        across = np.stack([-rel[:, 1], rel[:, 0]], axis=-1)  # r v: the range times the unit vector across the sight
        out += math.radians(heading_bias_deg) ** 2 * np.einsum("ka,kb->kab", across, across)
    return out[0] if single else out
