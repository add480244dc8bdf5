"""Which blocks of the radar's clutter map the chart says are land: kept out of the clutter level.

The clutter map (:mod:`tdm.frontend.radar_clutter`) takes a plot's local clutter level as a high
quantile of block maxima over an annulus 183 deg wide in azimuth: wide, so that sea clutter, which
varies mostly with range, is well sampled and a few targets fill few of its blocks. Near a coast the
annulus also takes in the land's own echo at the plot's range: on busy_port (seed 31, sweep 2) the
quays at 490 m, 35-65 deg off a sail boat's bearing, filled more than a tenth of the annulus with
video level 11-13, so the sail boat's clean level-7 echo (0 all around it) stood 5 dB *under* its
"clutter" and was never plotted; the TDM learnt of it only from its AIS 19 s later.

A radar that knows its chart keeps land out of its clutter statistics (land masking of the clutter
map: the sea's clutter is estimated over sea cells only; Skolnik, *Radar Handbook*, 3rd ed., ch. 7,
"clutter maps" and land/sea masking of CFAR). So, when the recording carries land, each block whose
centre lies within the chart's land grown by the beam's smear (:func:`tdm.land.beam_margin_m` with
``land_beam_fraction``, as the plots near land are dropped) plus half the block's width across the
beam, and which holds an echo (its maximum at least ``min_seed_db``: the land's own echo, not its
shadow), is left out of the annulus of every plot clear of the land. A plot is clear of the land
when its peak block lies more than a whole beamwidth (``land_clear_beam_fraction``) plus half a block
from it; a plot nearer keeps the land in its clutter level, since it may be the land's own echo
smeared beyond the dropping margin (a strong coast's echo still stands 15-20 dB over the noise a beamwidth
off). On busy_port seed 31 without that condition, four more radar-only false targets appeared 20-23 m
off the quays, when plots were dropped within half a beam of the land. Since ``land_beam_fraction`` is
a whole beam too (2026-11-28), a plot whose position lies that near is dropped anyway; the condition
still decides for a plot whose peak lies nearer the land than its position, and with a smaller
dropping margin. A plot whose whole annulus is land is measured against the thermal noise mean
(0 dB). Without land (open sea) nothing changes.
"""

from __future__ import annotations

import numpy as np
import shapely

from tdm.frames import Mount, OwnshipTrack
from tdm.land import LandMask, beam_margin_m

__all__ = ["land_blocks"]


def land_blocks(land: LandMask, candidates: np.ndarray, spokes_per_block: int, samples_per_block: int,
                azimuth_deg: np.ndarray, heading_deg: np.ndarray, time_s: np.ndarray, range_m: np.ndarray,
                track: OwnshipTrack, mount: Mount, beam_fraction: float, beam_az_deg: float) -> np.ndarray:
    """(sb, nb) bool: the clutter-map blocks whose echo the chart says is land's (module docstring).

    Parameters
    ----------
    land : LandMask
        The chart's land in the TDM's ENU frame (with the detections' margin).
    candidates : (sb, nb) bool
        The blocks to test (those holding an echo); the others are not land.
    spokes_per_block, samples_per_block : int
        A block's size in spokes of the sweep and in samples.
    azimuth_deg, heading_deg, time_s : (S,) float
        Per spoke: antenna azimuth from the bow, own-ship heading (compass deg) and time (s).
    range_m : (N,) float
        Range of each sample, m.
    track : OwnshipTrack
        The own ship's navigation (the antenna's position at each block's centre spoke).
    mount : Mount
        The radar's mounting.
    beam_fraction, beam_az_deg : float
        The beam's smear about the land (:func:`tdm.land.beam_margin_m`).

    Returns
    -------
    (sb, nb) bool
    """
    n_spokes, n_samples = azimuth_deg.shape[0], range_m.shape[0]
    out = np.zeros(candidates.shape, dtype=bool)
    bi, bj = np.nonzero(candidates)
    if bi.size == 0:
        return out
    spoke = np.minimum(bi * spokes_per_block + spokes_per_block // 2, n_spokes - 1)
    sample = np.minimum(bj * samples_per_block + samples_per_block // 2, n_samples - 1)
    bearing_rad = np.radians(azimuth_deg[spoke].astype(np.float64) + heading_deg[spoke].astype(np.float64))
    antenna = track.sensor_to_enu(np.zeros((bi.size, 3)), time_s[spoke].astype(np.float64), mount)[:, :2]
    block_range = range_m[sample].astype(np.float64)
    east = antenna[:, 0] + block_range * np.sin(bearing_rad)
    north = antenna[:, 1] + block_range * np.cos(bearing_rad)
    half_width_m = block_range * np.radians(360.0 * spokes_per_block / n_spokes) / 2.0
    margin_m = beam_margin_m(block_range, beam_fraction, beam_az_deg) + half_width_m
    out[bi, bj] = shapely.dwithin(land.geometry, shapely.points(east, north), margin_m)  # prepared: fast
    return out
