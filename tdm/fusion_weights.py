"""What the fusion's output weighs: the per-sensor tracks' states as :class:`tdm.fusion.Fuser` reports them.

Each function takes ``states`` ({(sensor, track id): ((6,) state, (6, 6) covariance)}, :mod:`tdm.ekf`) and
returns it with some tracks' entries replaced (new arrays; the tracks and the input untouched). The gates and
absorbing radii keep the filters' own states; only the reported fusion sees these.
"""

from __future__ import annotations

import math

import numpy as np

from tdm import ekf
from tdm.hull import BEAM_PER_LENGTH, hull_covariance

__all__ = ["face_turn_speed_sigma_mps", "member_hull_covariance", "with_extent", "with_face_turn", "with_fragments",
           "with_hull"]

#: Smallest speed a track's course share of the face turn is divided by, m/s (a still object's course is unknown).
COURSE_SPEED_FLOOR_MPS = 0.5


def with_extent(states: dict, live: dict) -> dict:
    """``states`` with each track's centre uncertainty behind the side seen (``Track.extent_var_m2``, m^2 per axis)
    added to its position covariance (``FusionConfig.weigh_extent``)."""
    out = dict(states)
    for key, tr in live.items():
        if tr.extent_var_m2 > 0.0:
            x, p = states[key]
            p = p.copy()
            p[:2, :2] += tr.extent_var_m2 * np.eye(2)
            out[key] = (x, p)
    return out


def with_hull(states: dict, live: dict, targets: list, lengths_by_mmsi: dict[int, float],
              beams_by_mmsi: dict[int, float], sigmas: float, sensors: tuple[str, ...] = ("radar",)) -> dict:
    """``states`` with the hull's variance (:func:`tdm.hull.hull_covariance`) added to the position covariance of
    the members of ``sensors`` of every target whose AIS track's MMSI has a known length (``FusionConfig.weigh_hull``).

    A radar track may lie anywhere on the hull (its plots are smeared by the beam); a LiDAR track lies at the middle
    of the part of the hull it sees, so anywhere on the hull less that part: the hull's length is taken less the
    LiDAR track's own length (its clusters' smoothed extent), down to nothing.

    Parameters
    ----------
    targets : list of FusedTarget
    lengths_by_mmsi, beams_by_mmsi : dict of int to float
        AIS static length and beam, m.
    sigmas : float
        Standard deviations of course uncertainty the hull's orientation spans (:func:`hull_covariance`).
    sensors : tuple of str
        The sensors whose members are weighed so.
    """
    out = None
    for target in targets:
        ais_key = ("ais", target.members.get("ais", -1))
        if ais_key not in live:
            continue
        for sensor in sensors:
            key = (sensor, target.members.get(sensor, -1))
            if key not in live:
                continue
            hull = member_hull_covariance(sensor, live[key], live[ais_key], states[ais_key], lengths_by_mmsi,
                                          beams_by_mmsi, sigmas)
            if hull is None:
                break  # the ship's length is not known
            out = dict(states) if out is None else out
            x, p = states[key]
            p = p.copy()
            p[:2, :2] += hull
            out[key] = (x, p)
    return states if out is None else out


def member_hull_covariance(sensor: str, member, ais_track, ais_state: tuple, lengths_by_mmsi: dict[int, float],
                           beams_by_mmsi: dict[int, float], sigmas: float) -> np.ndarray | None:
    """(2, 2) east-north covariance of where on an AIS ship's hull a member track of ``sensor`` may lie, m^2
    (:func:`with_hull`); None when the ship's length is not known.

    Parameters
    ----------
    sensor : str
    member, ais_track : Track
        The member track (a LiDAR track's ``length_m`` is the part of the hull it sees) and the ship's AIS track.
    ais_state : tuple of (6,) and (6, 6) float
        The AIS track's state and covariance (its course orients the hull).
    lengths_by_mmsi, beams_by_mmsi : dict of int to float
    sigmas : float
    """
    length_m = lengths_by_mmsi.get(ais_track.mmsi, math.nan)
    if not math.isfinite(length_m):
        return None
    beam_m = beams_by_mmsi.get(ais_track.mmsi, math.nan)
    seen_m = member.length_m if sensor == "lidar" and math.isfinite(member.length_m) else 0.0
    return hull_covariance(max(length_m - seen_m, 0.0), beam_m if math.isfinite(beam_m) else BEAM_PER_LENGTH * length_m,
                           ais_state[0], ais_state[1], sigmas)


def with_fragments(states: dict, targets: list, sensors: tuple[str, ...] = ("radar",)) -> dict:
    """``states`` with the member of ``sensors`` of every target without AIS that has absorbed tracks of the same
    sensor put at the mean position of the member and those tracks, their scatter added to its covariance.

    A large object (a ship end-on, a pier with a ship alongside, a tanker) paints several plots and so several
    tracks; the target follows the oldest, on one part of it, and absorbs the others (:class:`tdm.fusion.Fuser`).
    The object's centre lies among its parts: their mean, with their scatter (the population covariance of the
    positions, m^2) as the uncertainty of where among them the centre is.

    Parameters
    ----------
    states : dict
        (sensor, track id) -> ((6,), (6, 6)).
    targets : list of FusedTarget
    sensors : tuple of str
        The sensors whose members are moved.
    """
    out = None
    for target in targets:
        if "ais" in target.members or not target.absorbed:
            continue
        for sensor in sensors:
            key = (sensor, target.members.get(sensor, -1))
            parts = [k for k in target.absorbed if k[0] == sensor and k in states]
            if key not in states or not parts:
                continue
            xy = np.array([states[k][0][:2] for k in (key, *sorted(parts))])
            centre = xy.mean(axis=0)
            scatter = (xy - centre).T @ (xy - centre) / xy.shape[0]
            x, p = states[key]
            x, p = x.copy(), p.copy()
            x[:2] = centre
            p[:2, :2] += scatter
            out = dict(states) if out is None else out
            out[key] = (x, p)
    return states if out is None else out


def face_turn_speed_sigma_mps(x: np.ndarray, offset_sigma_m: np.ndarray, own_position_m: np.ndarray,
                              own_velocity_mps: np.ndarray) -> np.ndarray:
    """Standard deviation of the velocity a track takes from its seen side turning with the line of sight, m/s.

    A sensor that sees an object's near side tracks the middle of that side, which lies an offset (of standard
    deviation ``offset_sigma_m``) from the object's centre toward the sensor. As the own ship moves past, the line
    of sight turns at ``omega = |los x v_rel| / range^2`` (rad/s, ``v_rel`` the object's velocity less the own
    ship's) and the offset turns with it: the tracked point moves at ``offset omega`` across the line of sight
    though the object may not move at all.

    Parameters
    ----------
    x : (K, 6) float
        The tracks' states (:mod:`tdm.ekf`).
    offset_sigma_m : (K,) float
        Standard deviation of each track's offset from the object's centre, m.
    own_position_m, own_velocity_mps : (2,) float
        The own ship's east and north, m, and its velocity, m/s.

    Returns
    -------
    (K,) float
        m/s; 0 within 1 m of the own ship.
    """
    x = np.asarray(x, dtype=float).reshape(-1, ekf.N_STATES)
    los = x[:, :2] - np.asarray(own_position_m, dtype=float)[:2]
    v_rel = ekf.velocity_en(x) - np.asarray(own_velocity_mps)[:2]
    range2 = np.einsum("ki,ki->k", los, los)
    cross = np.abs(los[:, 0] * v_rel[:, 1] - los[:, 1] * v_rel[:, 0])
    omega = np.divide(cross, range2, out=np.zeros_like(cross), where=range2 > 1.0)
    return np.asarray(offset_sigma_m, dtype=float) * omega


def with_face_turn(states: dict, live: dict, own_position_m: np.ndarray, own_velocity_mps: np.ndarray,
                   scale: float, sensors: tuple[str, ...] = ("lidar",)) -> dict:
    """``states`` with the velocity a track of ``sensors`` takes from its seen side turning
    (:func:`face_turn_speed_sigma_mps`; the offset's standard deviation ``scale`` times the root of the track's
    ``Track.extent_var_m2``) added to its speed's variance, and over its speed (not under
    :data:`COURSE_SPEED_FLOOR_MPS`) to its course's (``FusionConfig.face_turn_scale``).

    Parameters
    ----------
    states : dict
        (sensor, track id) -> ((6,), (6, 6)).
    live : dict
        (sensor, track id) -> Track.
    own_position_m, own_velocity_mps : (2,) float
        m and m/s.
    scale : float
    sensors : tuple of str
    """
    keys = [k for k, tr in live.items() if k[0] in sensors and k in states and tr.extent_var_m2 > 0.0]
    if not keys or scale <= 0.0:
        return states
    x = np.array([states[k][0] for k in keys])
    offset = scale * np.sqrt([live[k].extent_var_m2 for k in keys])
    var = face_turn_speed_sigma_mps(x, offset, own_position_m, own_velocity_mps) ** 2
    course_var = var / np.maximum(np.abs(x[:, ekf.U]), COURSE_SPEED_FLOOR_MPS) ** 2
    out = dict(states)
    for k, key in enumerate(keys):
        p = states[key][1].copy()
        p[ekf.U, ekf.U] += var[k]
        p[ekf.PSI, ekf.PSI] += course_var[k]
        out[key] = (states[key][0], p)
    return out
