"""Sea clutter of the marine radar: mean level, wind-direction modulation, K-distributed texture and speckle.

Per revolution (numpy-vectorised, docs/radar.md section 3):

- mean: NRL ``sigma0`` (REF 3.7; Gregers-Hansen & Mital 2012) x the cell ``R theta3 dR sec psi`` through the radar
  equation, times the two-way vertical pattern at the sea cell's depression in the antenna frame, times the GIT
  wind-direction factor ``A_u / <A_u>`` (Horst, Dyer & Tuley 1978; :func:`radar_physics.git_wind_direction_db`):
  NRL's fit to Nathanson's tables is averaged over the look direction to the wind, the GIT factor restores the
  upwind / downwind / crosswind difference (about 5.8 dB upwind over downwind at X band, low grazing) keeping
  that average;
- texture: the sea's own Gaussian field (:class:`radar_texture.SeaTexture`) at each cell's world position,
  averaged over the beam, back to unit variance, mapped to Gamma(nu) with Ward's shape ``nu`` of EACH cell
  (grazing angle, resolved area, look direction against the swell; REF 3.8, Ward, Tough & Watts, *Sea Clutter*,
  2nd ed. 2013, section 2.7 / eq. 2.11), clamped only by the Gamma table's range [0.1, 20];
- speckle: exponential, fresh every spoke and cell; shadow: none at or behind the first object hit of a spoke.

Mean and texture change smoothly over a beamwidth, so they are formed on every ``sub``-th spoke and repeated.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.ndimage import uniform_filter1d

from raysim.random_streams import stream
from raysim.sensors import radar_physics as phys
from raysim.sensors.radar_texture import SeaTexture

__all__ = ["SeaClutter"]

DEG_PER_TURN = 360.0
#: Largest sea-clutter mean SNR, dB: far above video level 15 (about 55 dB) and far below float32's 385 dB.
MAX_CLUTTER_DB = 200.0
#: Smallest grazing angle the clutter formulas are evaluated at, deg (below it log terms run away).
MIN_GRAZING_DEG = 1e-3
#: Steepest grazing angle of the NRL sea-clutter fit, deg (REF 3.7: 0.1 to 60 deg).
NRL_MAX_GRAZING_DEG = 60.0
#: Clutter mean beyond the horizon, dB: none, but finite so that it can be interpolated.
NO_CLUTTER_DB = -300.0
#: Steps of the clutter mean and texture across one azimuth beamwidth (formed on every sub-th spoke).
CLUTTER_STEPS_PER_BEAM = 6
#: Antenna height step of the clutter table's slope, m (the table at h_mid +- this).
CLUTTER_HEIGHT_STEP_M = 0.05
#: Grazing angles above this, deg, get the exact arcsine in the vertical pattern (the first range bins).
STEEP_GRAZING_DEG = 10.0
#: Swell angle that makes Ward's swell term vanish (cos(2 x 45 deg) = 0), deg: the swell term is added per spoke.
NO_SWELL_DEG = 45.0
#: Range bins of the moving average that normalises the texture's standard deviation along range.
TEXTURE_STD_WINDOW_BINS = 33
#: Smallest texture value: the Gamma quantile of a very low normal at nu near 0.1 underflows float32 to 0, and a
#: texture of exactly 0 would make clutter / texture undefined.
TEXTURE_FLOOR = 1e-30
#: Ward's shape is evaluated unclamped here (the Gamma table clamps it to [NU_MIN, NU_MAX] per cell).
NU_UNCLAMPED = (1e-12, 1e12)


class SeaClutter:
    """Sea clutter of one radar: the mean-level table and the per-revolution K-distributed clutter.

    Parameters
    ----------
    range_m : (N,) float
        Range of each sample, m (``range_m[j] = j dR``).
    spokes : int
        Spokes per revolution S.
    cell_m : float
        Range extent of a clutter cell, m (``max(dR, range resolution)``).
    params : RadarParams-like
        Any object with ``f_ghz``, ``beam_az_deg``, ``beam_el_deg`` and ``polarisation``.
    sea_state : int
        Douglas sea state 0..6 (0: no texture, the mean level only).
    wind_from_deg : float
        Direction the wind (and, here, the swell) comes from, degrees clockwise from north.
    seed : int
        Scenario seed (the named streams ``radar.clutter.<rev>`` and ``radar.texture.<k>``).
    snr_kw : dict
        Keyword arguments of :func:`radar_physics.snr` (transmitter, antenna gain, receiver).
    """

    def __init__(self, range_m: np.ndarray, spokes: int, cell_m: float, params: Any, sea_state: int,
                 wind_from_deg: float, seed: int, snr_kw: dict):
        self.range_m = np.asarray(range_m, dtype=np.float32)
        dr = float(self.range_m[1] - self.range_m[0])
        self.r64 = np.maximum(self.range_m.astype(np.float64), 0.5 * dr)
        self.spokes, self.samples = int(spokes), self.range_m.size
        self.cell_m = float(cell_m)
        self.p = params
        self.sea_state = int(sea_state)
        self.seed = int(seed)
        self.snr_kw = snr_kw
        # REF 3.7 cell: the -3 dB width (R theta3 dR sec psi)
        self.beam_eq_rad = math.radians(params.beam_az_deg)
        wind_rad = math.radians(wind_from_deg)
        self.wind_from_en = np.array([math.sin(wind_rad), math.cos(wind_rad)])  # east, north: towards the wind
        self.gamma = phys.GammaQuantiles()
        self.texture_field = SeaTexture(self.seed, self.sea_state, wind_from_deg)
        self.beam_spokes = params.beam_az_deg / (DEG_PER_TURN / self.spokes)
        sub = max(1, int(self.beam_spokes // CLUTTER_STEPS_PER_BEAM))  # 4 at 2048 spokes and 5.2 deg
        while self.spokes % sub:
            sub -= 1
        self.sub = sub
        self.rows = np.arange(0, self.spokes, sub)

    # ------------------------------------------------------------------ mean level

    def grazing_deg(self, antenna_h_m) -> tuple[np.ndarray, np.ndarray]:
        """Grazing angle of each range (4/3 earth) and the same clipped for the formulas.

        Returns
        -------
        psi : (..., N) float64, deg, NaN beyond the horizon
        psi_c : (..., N) float64, deg, at least MIN_GRAZING_DEG (1 deg beyond the horizon)
        """
        psi = phys.grazing_angle_deg(np.asarray(antenna_h_m, dtype=float)[..., None], self.r64)
        return psi, np.where(np.isfinite(psi), np.maximum(psi, MIN_GRAZING_DEG), 1.0)

    def mean_db_table(self, antenna_h_m: np.ndarray) -> np.ndarray:
        """(H, N) mean sea clutter, dB re. noise, at the level boresight: NRL sigma0 x cell area (no pattern, no wind).

        Parameters
        ----------
        antenna_h_m : (H,) float
            Antenna heights above the sea, m.
        """
        psi, psi_c = self.grazing_deg(antenna_h_m)
        area = phys.clutter_cell_area_m2(self.r64, psi_c, self.beam_eq_rad, self.cell_m)
        # the NRL fit holds from 0.1 to 60 deg grazing (REF 3.7); steeper cells (the first metres) keep the 60 deg value
        sigma0_db = phys.nrl_sigma0_db(np.minimum(psi_c, NRL_MAX_GRAZING_DEG), self.p.f_ghz, self.sea_state,
                                       self.p.polarisation)
        mean_db = sigma0_db + phys.db(area) + phys.snr_db(1.0, self.r64, **self.snr_kw)
        return np.where(np.isfinite(psi), mean_db, NO_CLUTTER_DB)  # beyond the horizon: none (finite, for interpolation)

    def ward_log_nu(self, psi_c_deg: np.ndarray, cos_swell: np.ndarray) -> np.ndarray:
        """(R, N) natural log of Ward's K shape of each cell, unclamped (REF 3.8).

        ``log10 nu = 2/3 log10 psi + 5/8 log10 A_c - k_pol - cos(2 theta_sw) / 3``.

        Parameters
        ----------
        psi_c_deg : (N,) float
            Grazing angle, deg (clipped, :meth:`grazing_deg`).
        cos_swell : (R,) float
            Cosine of the look direction against the swell, per spoke (``cos 2 theta_sw = 2 cos^2 - 1``).
        """
        area = phys.clutter_cell_area_m2(self.r64, psi_c_deg, self.beam_eq_rad, self.cell_m)
        log_nu_45 = np.log(phys.ward_shape_nu(psi_c_deg, area, self.p.polarisation, NO_SWELL_DEG, *NU_UNCLAMPED))
        cos_2sw = 2.0 * np.asarray(cos_swell, dtype=float) ** 2 - 1.0
        return (log_nu_45[None, :] - (math.log(10.0) / 3.0) * cos_2sw[:, None]).astype(np.float32)

    def _boresight(self, rot: np.ndarray, azimuth_deg: np.ndarray):
        """Horizontal boresight in the world (R, 2) east/north unit, the antenna's tilt along it and its up axis's z."""
        bearing = np.radians(azimuth_deg)
        dxy = np.stack([np.cos(bearing), -np.sin(bearing), np.zeros(bearing.size)], 1)  # sensor frame (FLU)
        bore = np.einsum("sij,sj->si", rot, dxy)
        bh = bore[:, :2] / np.maximum(np.linalg.norm(bore[:, :2], axis=1, keepdims=True), 1e-12)
        z_ax = rot[:, :, 2]  # the antenna's up axis in the world
        sin_tilt = (z_ax[:, 0] * bh[:, 0] + z_ax[:, 1] * bh[:, 1]).astype(np.float32)
        return bh, sin_tilt, z_ax[:, 2].astype(np.float32)

    def mean_rows(self, rot: np.ndarray, azimuth_deg: np.ndarray, antenna_h_m: np.ndarray, h_max_m: float):
        """(R, N) float32 linear mean clutter SNR on the formed spokes, their boresight (R, 2) and grazing (N,) deg.

        NRL x cell (linear in the antenna height about ``h_mid``, the mean over the revolution) + the two-way vertical
        pattern at the cell's depression in the antenna frame (roll and pitch included) + the GIT wind factor.

        Parameters
        ----------
        rot : (R, 3, 3) float
            Sensor -> world rotations of the formed spokes.
        azimuth_deg : (R,) float
            Antenna azimuths, deg clockwise from the bow.
        antenna_h_m : (S,) float
            Antenna height of every spoke of the revolution, m.
        h_max_m : float
            Highest antenna height of the revolution, m (no sea cell nearer than it).
        """
        h_rows = antenna_h_m[:: self.sub]
        h_mid = float(np.mean(antenna_h_m))
        table = self.mean_db_table(np.array([h_mid - CLUTTER_HEIGHT_STEP_M, h_mid + CLUTTER_HEIGHT_STEP_M]))
        slope = ((table[1] - table[0]) / (2.0 * CLUTTER_HEIGHT_STEP_M)).astype(np.float32)
        dh = (h_rows - h_mid).astype(np.float32)
        # (R, N) float32 arrays formed in place (two buffers); each sum and product is the same float32 operation
        mean_db = np.multiply(dh[:, None], slope[None, :])
        mean_db += table.mean(axis=0).astype(np.float32)[None, :]
        psi, psi_c = self.grazing_deg(h_mid)
        psi_r = np.radians(psi_c).astype(np.float32)
        bh, sin_tilt, z_up = self._boresight(rot, azimuth_deg)
        sin_el = np.multiply(np.cos(psi_r)[None, :], sin_tilt[:, None])
        work = np.multiply(np.sin(psi_r)[None, :], z_up[:, None])
        sin_el -= work
        # two-way Gaussian pattern in dB at the elevation asin(sin_el): ~ sin_el (0.5 % at 10 deg) except in the
        # first, steep range bins
        steep = int(np.count_nonzero(psi_c > STEEP_GRAZING_DEG))
        el_sq = np.multiply(sin_el, sin_el, out=work)
        el_sq[:, :steep] = np.arcsin(np.clip(sin_el[:, :steep], -1.0, 1.0)) ** 2
        el_sq *= np.float32(2.0 * phys.one_way_gain_db(math.degrees(1.0), self.p.beam_el_deg))
        mean_db += el_sq
        # wind direction (GIT): phi = 0 looking into the wind
        cos_up = (bh @ self.wind_from_en).astype(np.float32)
        gain_db, mean_gain_db = phys.git_wind_direction_db(psi_c, self.p.f_ghz)
        wind_db = np.multiply(gain_db.astype(np.float32)[None, :], cos_up[:, None], out=work)
        wind_db -= mean_gain_db.astype(np.float32)[None, :]
        mean_db += wind_db
        # no sea is nearer than the antenna is high: there the grazing geometry has no solution and the table runs
        # away (278 dB at the antenna, 150 dB jumps per 0.1 m of height, overflowing float32 with the heave's slope;
        # an inf poisons the FTC filter down the whole spoke); the cap keeps the rest of float32 finite
        mean_db[:, : int(np.count_nonzero(self.range_m <= h_max_m))] = -np.inf  # range_m increases from 0
        np.minimum(mean_db, np.float32(MAX_CLUTTER_DB), out=mean_db)
        mean_db *= np.float32(math.log(10.0) / 10.0)  # 10^(x/10) as exp(x ln10/10): float32 exp is vectorised
        return np.exp(mean_db, out=mean_db), bh, cos_up, psi_c

    # ------------------------------------------------------------------ texture and the revolution

    def texture_rows(self, pos: np.ndarray, bh: np.ndarray, cos_up: np.ndarray, psi_c_deg: np.ndarray,
                     time_s: float) -> np.ndarray:
        """(R, N) float32 Gamma texture (mean 1) of the formed spokes, with Ward's shape of each cell.

        Parameters
        ----------
        pos : (R, 2+) float
            Antenna position (east, north, ...) of the formed spokes, m.
        bh : (R, 2) float
            Horizontal boresight (east, north) unit vectors.
        cos_up : (R,) float
            Cosine of the look direction against the wind (and swell): 1 upwind.
        psi_c_deg : (N,) float
            Grazing angle of each range, deg.
        time_s : float
            Time of the revolution's texture, s.
        """
        # the cells range by range (N, R): the moving average over azimuth below runs along memory
        rng32 = self.range_m[:, None]
        east = pos[None, :, 0].astype(np.float32) + bh[None, :, 0].astype(np.float32) * rng32
        north = pos[None, :, 1].astype(np.float32) + bh[None, :, 1].astype(np.float32) * rng32
        zt = self.texture_field.sample(east, north, time_s)
        # two passes of a moving average over one beamwidth (circular in azimuth; on the transposed, contiguous
        # array), then unit variance again at each range: the marginal is standard normal again
        width = max(1, int(round(self.beam_spokes / self.sub)))
        zt = uniform_filter1d(uniform_filter1d(zt, width, axis=1, mode="wrap"), width, axis=1, mode="wrap")
        std = np.maximum(uniform_filter1d(zt.std(axis=1), TEXTURE_STD_WINDOW_BINS, mode="nearest"), 1e-6)
        zt /= std[:, None]  # a fresh array from the filter: divided in place
        z = np.ascontiguousarray(zt.T)
        texture = self.gamma(z, self.ward_log_nu(psi_c_deg, cos_up))
        return np.maximum(texture, np.float32(TEXTURE_FLOOR), out=texture)

    def render(self, rev: int, t: np.ndarray, rot: np.ndarray, pos: np.ndarray, azimuth_deg: np.ndarray,
               heading_deg: np.ndarray, antenna_h_m: np.ndarray, first_hit_m: np.ndarray | None,
               speckle: np.ndarray | None = None):
        """Sea clutter SNR of one revolution (K-distributed, zero in shadow and beyond the horizon) and its texture.

        Parameters
        ----------
        rev : int
            Revolution number (names the speckle stream).
        t : (S,) float
            Spoke times, s.
        rot : (S, 3, 3) float
            Sensor -> world rotation per spoke.
        pos : (S, 3) float
            Antenna position per spoke (local ENU), m.
        azimuth_deg : (S,) float
            Antenna azimuth per spoke, deg clockwise from the bow.
        heading_deg : (S,) float
            Own-ship heading per spoke, deg (the look direction comes from ``rot``; kept for the interface).
        antenna_h_m : (S,) float
            Antenna height above the sea per spoke, m.
        first_hit_m : (S,) float or None
            Range of the first object hit per spoke, m (inf: none); None leaves the shadow to :meth:`shadow`.
        speckle : (S, N) float32, optional
            Exponential (mean 1) speckle to multiply by; by default drawn from the stream ``radar.clutter.<rev>``
            (and none at sea state 0).

        Returns
        -------
        clutter : (S, N) float32
            Sea clutter SNR, linear re. noise.
        texture : (S / sub, N) float32 or None
            The Gamma texture (mean 1) on the formed spokes (every ``sub``-th, repeated over the ``sub`` spokes
            from it); None at sea state 0.
        """
        S, N = self.spokes, self.samples
        rows = self.rows
        mean, bh, cos_up, psi_c = self.mean_rows(rot[rows], azimuth_deg[rows], antenna_h_m, float(np.max(antenna_h_m)))
        texture = None
        if self.sea_state > 0:
            texture = self.texture_rows(pos[rows], bh, cos_up, psi_c, float(t[S // 2]))
            mean *= texture
        if speckle is not None and self.sub > 1:  # each formed spoke's mean times the speckle of its sub spokes
            clutter = np.multiply(mean[:, None, :], speckle.reshape(S // self.sub, self.sub, N)).reshape(S, N)
        elif speckle is not None:
            clutter = mean
            clutter *= speckle
        else:
            clutter = np.repeat(mean, self.sub, axis=0) if self.sub > 1 else mean
        if speckle is None and texture is not None:
            clutter *= stream(self.seed, f"radar.clutter.{rev}").standard_exponential((S, N), dtype=np.float32)
        if first_hit_m is not None:
            self.shadow(clutter, first_hit_m)
        return clutter, texture

    def shadow(self, clutter: np.ndarray, first_hit_m: np.ndarray) -> None:
        """Radar shadow, in place: no sea echo at or behind the first object hit of each spoke.

        Parameters
        ----------
        clutter : (S, N) float32
            Sea clutter SNR of the revolution.
        first_hit_m : (S,) float
            Range of the first object hit per spoke, m (inf: none).
        """
        hit_rows = np.flatnonzero(np.isfinite(first_hit_m))
        if hit_rows.size:
            clutter[hit_rows] *= self.range_m[None, :] < first_hit_m[hit_rows, None]
