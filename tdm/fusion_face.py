"""A radar track's painted face and its object's centre behind it (:class:`tdm.fusion.Fuser`).

A radar paints the side of an object that faces it; the track of its plots stands on that face, and the
object's centre lies behind it along the line of sight by about half the object's size, the *hidden depth*
(docs/tdm.md, "Extended objects").

- **Still targets without AIS** (``radar_hidden_depth_*``): the radar track is moved its hidden depth behind the
  face, and the depth's variance is added along the line of sight (:func:`behind_the_face`).
- **Other targets without AIS** (``consider_radar_face``): the track is left on the face (a ship under way, a target
  not yet known to be still, or a track that joined a still target during the step), and the offset it carries, the
  hidden depth squared plus its variance along the line of sight, is reported in the target's covariance as a
  consider term (:func:`face_covariance`; :func:`tdm.fusion_rules.consider_covariance`), not fed to the fusion's
  weights or gates.
- **The radar's own tracks** (``radar_track_face_covariance``): in ``sensor_tracks.jsonl`` each radar track reports
  the same face offset, along the line of sight, in place of a fraction of its length per axis
  (:func:`face_report`); it knows nothing of AIS or of being still, so every radar track does. A LiDAR or radar
  track reports the own ship's navigation bias too (:func:`sensor_report`, :mod:`tdm.nav_bias`).

A target with AIS takes its hull's spread instead (:func:`tdm.fusion_weights.with_hull`).
"""

from __future__ import annotations

import math

import numpy as np

from tdm.fusion_config import FusionConfig
from tdm.fusion_target import FusedTarget
from tdm.hull import UNIFORM_VARIANCE_DIVISOR
from tdm.nav_bias import NAV_RELATIVE_SENSORS, nav_bias_covariance
from tdm.tracker import Track


#: Classes of targets that do not move: an ended one is looked for where it was for ``revive_still_s``, and their
#: radar tracks are moved behind their face.
STILL_DESCRIPTORS = frozenset({"iceberg", "fixed obstacle"})


def hidden_depth_m(track: Track, distance_m: float, config: FusionConfig) -> tuple[float, float]:
    """How far a radar track's object's centre lies behind its plots, and that depth's standard deviation, m.

    Fractions of its plots' core width where that spans ``radar_core_width_min_beams`` beamwidths at ``distance_m``
    (m) or more (``radar_hidden_depth_size="core_width"``), else of its length.
    """
    core_m, beam_deg = track.core_width_m, config.radar_beam_deg
    if config.radar_hidden_depth_size == "core_width" and np.isfinite(core_m) and \
            core_m >= config.radar_core_width_min_beams * distance_m * math.radians(beam_deg or 0.0):
        return config.radar_hidden_depth_fraction * core_m, config.radar_hidden_depth_sigma_fraction * core_m
    return (config.radar_hidden_depth_length_fraction * track.length_m,
            config.radar_hidden_depth_length_sigma_fraction * track.length_m)


def behind_the_face(targets: list[FusedTarget], states: dict, live: dict, own_m: np.ndarray,
                    config: FusionConfig) -> set[tuple[str, int]]:
    """Move the radar tracks of still targets without AIS along the line of sight by their hidden depth.

    Parameters
    ----------
    targets : list of FusedTarget
    states : dict
        ``(sensor, track id) -> (x (6,), p (6, 6))`` at the step's time; the radar tracks moved are replaced, with
        the variance of their depth added along the line of sight (the tracks themselves are untouched).
    live : dict
        ``(sensor, track id) -> Track``.
    own_m : (2,) float
        Own ship's east and north, m.
    config : FusionConfig

    Returns
    -------
    set of (str, int)
        The keys of the radar tracks moved: their depth is in their state, not to be reported again by
        :func:`face_covariance` whatever target they end the step in.
    """
    moved: set[tuple[str, int]] = set()
    for target in targets:
        key = ("radar", target.members.get("radar", -1))
        if target.descriptor not in STILL_DESCRIPTORS or "ais" in target.members or key not in states:
            continue
        x, p = states[key]
        u, depth_m, sigma_m = _sight_and_depth(live[key], x, own_m, config)
        if u is not None and np.isfinite(depth_m):
            x, p = x.copy(), p.copy()
            x[:2] += depth_m * u
            p[:2, :2] += sigma_m ** 2 * np.outer(u, u)
            states[key] = (x, p)
            moved.add(key)
    return moved


def face_report(track: Track, t_s: float, own_m: np.ndarray | None, config: FusionConfig
                ) -> tuple[np.ndarray, np.ndarray]:
    """What a radar track reports in ``sensor_tracks.jsonl`` at ``t_s`` (s): its predicted state (6,) and covariance
    (6, 6), with its face offset (:func:`sight_covariance`) added to the position's covariance where
    ``radar_track_face_covariance`` is on and the own ship's position ``own_m`` (2,) (m) is known (not None,
    finite), else
    :meth:`tdm.tracker.Track.reported` (``extent_sigma_fraction`` of its length per axis)."""
    if not config.radar_track_face_covariance or own_m is None or not np.all(np.isfinite(own_m)):
        return track.reported(t_s)
    x, p = track.predicted(t_s)
    p = p.copy()
    p[:2, :2] += sight_covariance(track, x, own_m, config)
    return x, p


def sensor_report(sensor: str, track: Track, t_s: float, own_m: np.ndarray | None, config: FusionConfig
                  ) -> tuple[np.ndarray, np.ndarray]:
    """What a track of ``sensor`` reports in ``sensor_tracks.jsonl`` at ``t_s`` (s): its state (6,) and covariance
    (6, 6); a radar track's as :func:`face_report`, another's as :meth:`tdm.tracker.Track.reported`, and with the
    own ship's navigation bias added to a LiDAR or radar track's position covariance (``consider_nav_bias``,
    :func:`tdm.nav_bias.nav_bias_covariance`; ``own_m`` (2,) m, the own ship's position, None if unknown), a LiDAR
    track's range limit (:func:`range_cut_covariance`) and a radar track's echo fragment
    (``radar_track_fragment_covariance``, :func:`fragment_var_m2`)."""
    x, p = face_report(track, t_s, own_m, config) if sensor == "radar" else track.reported(t_s)
    nav = config.consider_nav_bias and sensor in NAV_RELATIVE_SENSORS
    cut = track.range_cut and track.range_cut_sigma_m > 0.0
    fragment = fragment_var_m2(track) if sensor == "radar" and config.radar_track_fragment_covariance else 0.0
    if nav or cut or fragment > 0.0:
        p = p.copy()
    if fragment > 0.0:
        p[:2, :2] += fragment * np.eye(2)
    if nav:
        p[:2, :2] += nav_bias_covariance(x[:2], own_m, config.nav_position_bias_m, config.nav_heading_bias_deg)
    if cut:
        p[:2, :2] += range_cut_covariance(x[:2], own_m, track.range_cut_sigma_m)
    return x, p


def fragment_var_m2(track: Track) -> float:
    """Variance per axis, m^2, of a radar track's object's centre along the echo its plots are fragments of: its echo
    spread (:attr:`tdm.tracker.Track.echo_spread_m`) squared over 12, a point anywhere on it; 0 for a track whose
    plots are their echoes (or a track of another sensor: NaN spread)."""
    spread_m = track.echo_spread_m
    return float(spread_m ** 2 / UNIFORM_VARIANCE_DIVISOR) if np.isfinite(spread_m) and spread_m > 0.0 else 0.0


def range_cut_covariance(position_m: np.ndarray, own_m: np.ndarray | None, sigma_m: float) -> np.ndarray:
    """(2, 2) covariance, m^2: ``sigma_m`` along the line of sight from ``own_m`` (2,) to ``position_m`` (2,), m, for
    a track whose object may go on beyond the sensor's range limit (:attr:`tdm.tracker.TrackerConfig.range_cut_sigma_m`);
    ``sigma_m`` per axis where the own ship is unknown (None or not finite) or on the track."""
    u = None if own_m is None else _sight(position_m, own_m)[0]
    return sigma_m ** 2 * (np.eye(2) if u is None else np.outer(u, u))


def sight_covariance(track: Track, x: np.ndarray, own_m: np.ndarray, config: FusionConfig) -> np.ndarray:
    """(2, 2) covariance, m^2, of a radar track's offset from its object's centre, along the line of sight from
    ``own_m`` (2,) to the track's position ``x[:2]`` (m): its hidden depth (:func:`hidden_depth_m`) squared plus
    the depth's variance; zero where the depth is not finite or the track lies on the own ship."""
    u, depth_m, sigma_m = _sight_and_depth(track, x, own_m, config)
    if u is not None and np.isfinite(depth_m) and np.isfinite(sigma_m):
        return (depth_m ** 2 + sigma_m ** 2) * np.outer(u, u)
    return np.zeros((2, 2))


def _sight_and_depth(track: Track, x: np.ndarray, own_m: np.ndarray, config: FusionConfig
                     ) -> tuple[np.ndarray | None, float, float]:
    """The unit line of sight (2,) from ``own_m`` (2,, m) to the track's position ``x[:2]`` (m), None where the
    track lies on the own ship, and the track's hidden depth and its standard deviation there, m
    (:func:`hidden_depth_m`)."""
    u, distance = _sight(x, own_m)
    depth_m, sigma_m = hidden_depth_m(track, distance, config)
    return u, depth_m, sigma_m


def _sight(position_m: np.ndarray, own_m: np.ndarray) -> tuple[np.ndarray | None, float]:
    """The unit line of sight (2,) from ``own_m`` (2,, m) to ``position_m[:2]`` (m), None where they coincide or
    either is not finite, and the distance, m."""
    sight = np.asarray(position_m, dtype=float)[:2] - np.asarray(own_m, dtype=float)[:2]
    distance = float(np.hypot(*sight))
    return (sight / distance if distance > 0.0 else None), distance


def face_covariance(target: FusedTarget, moved: bool, x: np.ndarray, track: Track, own_m: np.ndarray | None,
                    config: FusionConfig) -> np.ndarray:
    """Covariance of the offset of a radar track left on its face from its object's centre.

    Parameters
    ----------
    target : FusedTarget
        The track's target at the end of the step.
    moved : bool
        Whether :func:`behind_the_face` moved the track at the start of the step (its depth is in its state).
    x : (6,) float
        The track's state at the step's time (position east, north, m).
    track : Track
    own_m : (2,) float or None
        Own ship's east and north, m; None: unknown (zero returned).
    config : FusionConfig

    Returns
    -------
    (2, 2) float
        m^2: for a track not moved, of a target without AIS, the hidden depth (:func:`hidden_depth_m`) squared plus
        its variance, along the line of sight; else zero. Membership is that at the end of the step: a track that
        joined a still target during it is widened, not left bare, and one moved at the start and then merged into
        a vessel's target is not widened again.
    """
    if own_m is None or moved or "ais" in target.members:
        return np.zeros((2, 2))
    return sight_covariance(track, x, own_m, config)
