"""The covariance a fused target reports: its fusion's, with the biases its members' positions carry taken through
the fusion's weights (:class:`tdm.fusion.Fuser`; :func:`tdm.fusion_rules.consider_covariance`).

Four biases, each a "consider" term (as in the Schmidt-Kalman filter: a slowly changing offset, not noise, kept out
of the fusion's weights and gates and reported):

- a LiDAR track's centre behind the side it sees (``consider_lidar_extent``; :attr:`tdm.tracker.Track.extent_var_m2`
  per axis);
- a radar track left on the face it paints (``consider_radar_face``; :func:`tdm.fusion_face.face_covariance`), and
  one on a fragment of a longer echo (``consider_radar_fragment``; :func:`tdm.fusion_face.fragment_var_m2`);
- the own ship's navigation bias, one bias shared by every LiDAR and radar member (``consider_nav_bias``;
  :mod:`tdm.nav_bias`).
"""

from __future__ import annotations

import numpy as np

from tdm.fusion_config import FusionConfig
from tdm.fusion_face import face_covariance, fragment_var_m2
from tdm.fusion_rules import apart_members, consider_covariance, velocity_frame
from tdm.fusion_target import FusedTarget
from tdm.nav_bias import NAV_RELATIVE_SENSORS, nav_bias_covariance


__all__ = ["reported_covariance"]


def reported_covariance(target: FusedTarget, x: np.ndarray, p: np.ndarray, xs: np.ndarray, ps: np.ndarray,
                        live: dict, own_m: np.ndarray | None, moved: set[tuple[str, int]],
                        config: FusionConfig) -> np.ndarray:
    """The target's fused covariance with its members' biases considered.

    Parameters
    ----------
    target : FusedTarget
        Its members at the end of the step.
    x : (6,) float
        The target's fused state (position east, north, m).
    p : (6, 6) float
        Its fused covariance.
    xs : (K, 6) float
        The members' states as the fusion weighed them, in the order of ``target.members``.
    ps : (K, 6, 6) float
        Their covariances as the fusion weighed them (a velocity the AIS rules out left out,
        :meth:`tdm.fusion.Fuser._members`), so that the considered biases go through the fusion's own weights.
    live : dict
        ``(sensor, track id) -> Track``.
    own_m : (2,) float or None
        Own ship's east and north, m; None: unknown (no face offset, the navigation's position bias alone).
    moved : set of (str, int)
        The radar tracks :func:`tdm.fusion_face.behind_the_face` moved this step (their depth is in their state).
    config : FusionConfig

    Returns
    -------
    (6, 6) float
        ``p`` plus the considered terms; ``p`` itself where there are none.
    """
    keys = list(target.members.items())
    v = np.zeros((len(keys), 2, 2))
    for n, key in enumerate(keys):
        if key[0] == "lidar" and config.consider_lidar_extent:
            v[n] = live[key].extent_var_m2 * np.eye(2)
        elif key[0] == "radar":
            if config.consider_radar_face:
                v[n] = face_covariance(target, key in moved, xs[n], live[key], own_m, config)
            if config.consider_radar_fragment:
                v[n] += fragment_var_m2(live[key]) * np.eye(2)
    shared = np.array([key[0] in NAV_RELATIVE_SENSORS for key in keys])
    nav = None
    if config.consider_nav_bias and shared.any():
        nav = nav_bias_covariance(x[:2], own_m, config.nav_position_bias_m, config.nav_heading_bias_deg)
    if not np.any(v > 0.0) and (nav is None or not np.any(nav > 0.0)):
        return p
    return p + consider_covariance(xs, ps, v, config.rule, nav, shared,
                                   velocity_frame(config.fuse_velocity, target.members),
                                   apart_members(target.members, config.fuse_position_apart))
