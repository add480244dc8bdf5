"""Radar plots that are sidelobe echoes of a stronger plot at the same range, found and dropped.

A strong reflector (a ship's side, a pier, a coast face) is received through the antenna's
sidelobes on the spokes either side of its bearing: an arc at its range, tens of decibels under its
main-lobe echo (docs/radar.md, "Antenna": one way -21 dB at 6 deg, -25..-30 dB to 30 deg, -35 dB at
60 deg; two way twice that). Where the arc rises over the local clutter it makes plots that the
trackers would follow as targets: on the held-out harbour_approach seed 31 half of the false radar-only
reports (126 of 253) had a plot at least 10 dB stronger at the same range 3-60 deg away, against 13 % of
the true ones (docs/tdm.md). A real set suppresses them the same way: an echo much weaker than one at
the same range a few beamwidths off is taken as that echo's sidelobe.

Rule, per scan: plot ``i`` is a sidelobe of plot ``j`` when

- ``|range_j - range_i| <= range_gate_m`` (a sidelobe lies at its source's range),
- ``min_offset_deg <= |bearing_j - bearing_i| <= max_offset_deg`` (outside the main lobe, inside the
  sidelobes that a saturating echo can lift over the video floor: the two-way pattern is -70 dB at
  60 deg, under the floor for the strongest echo the radar equation gives, docs/radar.md), and
- ``strength_j - strength_i >= margin_db`` (the plots' strength over the local clutter, dB).

The defaults follow the antenna and the receiver, not a scenario (module :mod:`tdm.frontend.radar_config`
has the values and their reasons). A true target weaker by ``margin_db`` than a ship at its range and a
few beamwidths away is lost with the sidelobes; the other sensors and the next scans still see it.
"""

from __future__ import annotations

import numpy as np

from tdm.detections import Detections
from tdm.frames import Mount, OwnshipTrack

__all__ = ["drop_sidelobes", "sidelobe_plots"]


def sidelobe_plots(position_m: np.ndarray, sensor_m: np.ndarray, range_m: np.ndarray, strength_db: np.ndarray,
                   range_gate_m: float, min_offset_deg: float, max_offset_deg: float, margin_db: float) -> np.ndarray:
    """Which plots of one scan are sidelobe echoes of a stronger plot (module docstring).

    Parameters
    ----------
    position_m : (N, 2) float
        Plot positions, ENU m.
    sensor_m : (N, 2) float
        The antenna's ENU position when each plot was seen, m.
    range_m : (N,) float
        Plot ranges from the antenna, m.
    strength_db : (N,) float
        Plot strengths over the local clutter, dB.
    range_gate_m, min_offset_deg, max_offset_deg, margin_db : float
        The rule's settings (module docstring).

    Returns
    -------
    (N,) bool
        True for the plots to drop.
    """
    n = range_m.shape[0]
    if n < 2:
        return np.zeros(n, dtype=bool)
    rel = position_m - sensor_m
    bearing_deg = np.degrees(np.arctan2(rel[:, 0], rel[:, 1]))
    offset_deg = np.abs((bearing_deg[None, :] - bearing_deg[:, None] + 180.0) % 360.0 - 180.0)  # (i, j)
    same_range = np.abs(range_m[None, :] - range_m[:, None]) <= range_gate_m
    stronger = strength_db[None, :] - strength_db[:, None] >= margin_db
    in_sidelobes = (offset_deg >= min_offset_deg) & (offset_deg <= max_offset_deg)
    return np.any(same_range & stronger & in_sidelobes, axis=1)


def drop_sidelobes(plots: Detections, track: OwnshipTrack, mount: Mount, config) -> Detections:
    """``plots`` (one radar scan) without its sidelobe echoes (module docstring); as they are when
    ``config.sidelobe_margin_db`` is None (the rule off).

    Parameters
    ----------
    plots : Detections
        One scan's radar plots (``strength_db`` set).
    track : OwnshipTrack
        The own ship's navigation (the antenna's position at each plot's time).
    mount : Mount
        The radar's mounting.
    config : RadarFrontEndConfig
        ``sidelobe_range_gate_m``, ``sidelobe_offset_deg`` (min, max) and ``sidelobe_margin_db``.
    """
    margin_db = config.sidelobe_margin_db
    if margin_db is None or len(plots) < 2 or plots.strength_db is None:
        return plots
    sensor_m = track.sensor_to_enu(np.zeros((len(plots), 3)), plots.time_s, mount)[:, :2]
    drop = sidelobe_plots(plots.position_m, sensor_m, plots.range_m, plots.strength_db,
                          config.sidelobe_range_gate_m, *config.sidelobe_offset_deg, margin_db)
    return plots.subset(~drop) if drop.any() else plots
