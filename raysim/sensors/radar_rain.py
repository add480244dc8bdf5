"""Rain for the marine radar: a uniform background plus EXCELL rain cells drifting with the wind.

The rain-rate field, mm/h, at a point ``(east, north)`` m of the local frame and time ``t`` s is

``R(x, t) = R_bg + sum_c R_p,c exp(-|x - x_c - v t| / r0_c)``

- ``R_bg`` is ``environment.rain_mm_per_h``: uniform stratiform rain over the whole scene.
- Each cell of ``environment.rain_cells`` is an EXCELL exponential cell (Capsoni, Fedi, Magistroni,
  Paraboni and Pawlina, "Data and theory for a new model of the horizontal structure of rain cells
  for propagation applications", Radio Science 22(3), 395-404, 1987): peak rate ``R_p``
  (``rate_mm_per_h``) at the centre, falling by 1/e every ``r0`` (``radius_m``). EXCELL's cells are
  elliptical and truncated where the rate falls to a threshold; here they are circular and
  untruncated (at ``5 r0`` the rate is 0.7 % of the peak).
- The cells drift with the wind at ``environment.wind_speed_mps`` towards ``wind_from_deg + 180``
  (convective cells move with the steering-level wind; the surface wind stands in for it).

Per revolution (all vectorised, :meth:`RainEchoes.revolution`):

- The field is evaluated once, at the revolution's middle time, on every ``sub``-th spoke (the
  rain changes little across a beamwidth) along each spoke's horizontal boresight, and repeated.
- Volume clutter mean per cell ``eta(R) V`` through the radar equation (REF 3.9: ``eta = pi^5 |K|^2 Z
  / lambda^4``, ``Z = 200 R^1.6``), with exponential speckle per spoke and sample (stream
  ``radar.rain.<rev>``).
- Two-way path attenuation to each range: ``A(r) = 2 int_0^r gamma(R(s)) ds`` dB with the ITU-R P.838
  specific attenuation ``gamma`` (REF 3.9), the integral a cumulative trapezoid along the spoke; it
  multiplies every echo of the spoke (objects, sea, rain).

With no cells the field is uniform and the per-range terms are formed once (the original uniform
model, byte for byte).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from raysim.random_streams import stream
from raysim.sensors import radar_physics as phys

M_PER_KM = 1000.0
DEG_PER_TURN = 360.0
#: Steps of the rain field across one azimuth beamwidth (it is formed on every sub-th spoke).
RAIN_STEPS_PER_BEAM = 6


def drift_velocity_mps(wind_speed_mps: float, wind_from_deg: float) -> np.ndarray:
    """(2,) east, north velocity of the rain cells, m/s: with the wind, towards ``wind_from_deg + 180``."""
    a = math.radians(wind_from_deg)
    return np.array([-wind_speed_mps * math.sin(a), -wind_speed_mps * math.cos(a)])


def two_way_path_loss_db(gamma_db_per_km: np.ndarray, dr_m: float) -> np.ndarray:
    """Two-way path attenuation to every range sample, dB: ``2 int_0^r gamma ds`` (cumulative trapezoid).

    Parameters
    ----------
    gamma_db_per_km : (..., N) array
        One-way specific attenuation at the samples ``j dr_m``, j = 0..N-1, dB/km.
    dr_m : float
        Sample spacing, m.

    Returns
    -------
    (..., N) array, dB, 0 at the first sample; for a uniform ``gamma`` exactly ``2 gamma r / 1000``.
    """
    g = np.asarray(gamma_db_per_km)
    cum = np.cumsum(g, axis=-1)
    trap = cum - 0.5 * (g[..., :1] + g)  # sum_{k<=j} g_k - (g_0 + g_j) / 2
    return (2.0 * dr_m / M_PER_KM) * trap


@dataclass(frozen=True)
class RainField:
    """The rain-rate field: uniform background plus drifting EXCELL exponential cells.

    Attributes
    ----------
    background_mm_per_h : float
        Uniform rate everywhere, mm/h.
    east_m, north_m : (C,) arrays
        Cell centres at t = 0 in the local frame, m.
    r0_m : (C,) array
        EXCELL 1/e radius of each cell, m.
    peak_mm_per_h : (C,) array
        Peak rate at each centre (added to the background), mm/h.
    velocity_mps : (2,) array
        East, north drift of every cell, m/s.
    """

    background_mm_per_h: float
    east_m: np.ndarray
    north_m: np.ndarray
    r0_m: np.ndarray
    peak_mm_per_h: np.ndarray
    velocity_mps: np.ndarray

    @classmethod
    def from_environment(cls, env, frame) -> "RainField":
        """The field of a scenario's ``environment`` block (cell positions through the local ``frame``)."""
        cells = tuple(getattr(env, "rain_cells", ()) or ())
        if cells:
            lat = np.array([c.position[0] for c in cells], dtype=float)
            lon = np.array([c.position[1] for c in cells], dtype=float)
            east, north = (np.asarray(v, dtype=float).reshape(-1) for v in frame.to_local(lat, lon))
        else:
            east = north = np.zeros(0)
        return cls(float(env.rain_mm_per_h), east, north,
                   np.array([c.radius_m for c in cells], dtype=float),
                   np.array([c.rate_mm_per_h for c in cells], dtype=float),
                   drift_velocity_mps(env.wind_speed_mps, env.wind_from_deg))

    @property
    def has_cells(self) -> bool:
        return self.east_m.size > 0

    def centres_m(self, t_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(C,) east and (C,) north of the cell centres at time ``t_s``, m."""
        return self.east_m + self.velocity_mps[0] * t_s, self.north_m + self.velocity_mps[1] * t_s

    def rate_mm_per_h(self, east_m: np.ndarray, north_m: np.ndarray, t_s: float) -> np.ndarray:
        """Rain rate at points of the local frame at time ``t_s``, mm/h (float32, the shape of ``east_m``)."""
        rate = np.full(np.shape(east_m), self.background_mm_per_h, dtype=np.float32)
        ce, cn = self.centres_m(t_s)
        for c in range(ce.size):  # a handful of cells; each is one vectorised pass over the grid
            d = np.hypot(east_m - np.float32(ce[c]), north_m - np.float32(cn[c]))
            rate += np.float32(self.peak_mm_per_h[c]) * np.exp(d * np.float32(-1.0 / self.r0_m[c]))
        return rate


class RainEchoes:
    """Rain attenuation and volume clutter of a radar, per revolution.

    Parameters
    ----------
    field : RainField
    range_m : (N,) array
        Sample ranges ``j dr``, m.
    volume_snr : (N,) array
        SNR (linear, re. noise) of a unit volume reflectivity ``eta = 1 m^2/m^3`` filling each range
        cell: the radar equation times the cell volume ``R theta3 dR min(R theta_el / 2, h_rain)``.
    f_ghz : float
        Radar frequency (the backscatter ``eta`` goes as ``lambda^-4``).
    spokes : int
    beam_az_deg : float
        -3 dB azimuth beamwidth: the field is formed every ``sub`` spokes, about a sixth of it.
    """

    def __init__(self, field: RainField, range_m: np.ndarray, volume_snr: np.ndarray, f_ghz: float, spokes: int,
                 beam_az_deg: float):
        self.field = field
        self.range_m = np.asarray(range_m, dtype=np.float32)
        self.dr = float(range_m[1] - range_m[0])
        self.volume_snr = np.asarray(volume_snr, dtype=np.float32)
        self.f_ghz = f_ghz
        self.eta_per_rate16 = float(phys.rain_eta_m2_per_m3(1.0, f_ghz))  # eta = this x R^1.6
        self.spokes = spokes
        sub = max(1, int((beam_az_deg / (DEG_PER_TURN / spokes)) // RAIN_STEPS_PER_BEAM))
        while spokes % sub:
            sub -= 1
        self.sub = sub
        self.active = field.has_cells or field.background_mm_per_h > 0
        # uniform background alone: the per-range terms once (the original uniform model)
        r = float(field.background_mm_per_h)
        r64 = np.maximum(self.range_m.astype(np.float64), 0.5 * self.dr)
        self.uniform_loss = phys.undb(-2.0 * float(phys.rain_attenuation_db_per_km(r)) / M_PER_KM * r64).astype(np.float32)
        self.uniform_mean = (phys.rain_eta_m2_per_m3(r, f_ghz) * self.volume_snr).astype(np.float32) if r > 0 else None

    def rate_grid(self, t_mid_s: float, pos_m: np.ndarray, bearing_deg: np.ndarray) -> np.ndarray:
        """(S_sub, N) rain rate, mm/h, along every ``sub``-th spoke's horizontal boresight at ``t_mid_s``.

        ``pos_m`` (S, >=2) antenna east, north per spoke, m; ``bearing_deg`` (S,) compass bearing of each
        spoke (heading + antenna azimuth).
        """
        rows = np.arange(0, self.spokes, self.sub)
        b = np.radians(bearing_deg[rows])
        east = (pos_m[rows, 0, None] + np.sin(b)[:, None] * self.range_m[None, :]).astype(np.float32)
        north = (pos_m[rows, 1, None] + np.cos(b)[:, None] * self.range_m[None, :]).astype(np.float32)
        return self.field.rate_mm_per_h(east, north, t_mid_s)

    def path_loss(self, rate_mm_per_h: np.ndarray) -> np.ndarray:
        """(..., N) two-way rain transmission (linear, <= 1) to every sample along the given rate profiles."""
        gamma = phys.rain_attenuation_db_per_km(rate_mm_per_h)
        return phys.undb(-two_way_path_loss_db(gamma, self.dr)).astype(np.float32)

    def revolution(self, seed: int, rev: int, t_s: np.ndarray, pos_m: np.ndarray, bearing_deg: np.ndarray):
        """The rain of one revolution: ``(loss, clutter)``.

        Returns
        -------
        loss : (S, N) or (1, N) float32 array or None
            Two-way transmission to multiply every echo by (None: no rain).
        clutter : (S, N) float32 array or None
            Rain volume clutter, SNR linear re. noise, speckled (stream ``radar.rain.<rev>``).
        """
        if not self.active:
            return None, None
        shape = (self.spokes, self.range_m.size)
        if not self.field.has_cells:
            clutter = None
            if self.uniform_mean is not None:
                clutter = self.uniform_mean[None, :] * stream(seed, f"radar.rain.{rev}").standard_exponential(shape, dtype=np.float32)
            return self.uniform_loss[None, :], clutter
        rate = self.rate_grid(float(t_s[t_s.size // 2]), pos_m, bearing_deg)
        loss = self.path_loss(rate)
        mean = (np.float32(self.eta_per_rate16) * np.power(rate, np.float32(phys.Z_R_B))) * self.volume_snr[None, :]
        if self.sub > 1:
            loss = np.repeat(loss, self.sub, axis=0)
            mean = np.repeat(mean, self.sub, axis=0)
        clutter = mean * stream(seed, f"radar.rain.{rev}").standard_exponential(shape, dtype=np.float32)
        return loss, clutter


__all__ = ["RainEchoes", "RainField", "drift_velocity_mps", "two_way_path_loss_db"]
