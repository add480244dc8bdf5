"""The marine radar's link budget: radar equation, antenna pattern, rain (REFERENCE.md section 3).

- FMCW radar equation (item 1): ``SNR = Pt G^2 lambda^2 sigma T F^4 / ((4 pi)^3 R^4 k T0 Fn L)``
  with k T0 = -174 dBm/Hz. Defaults (Pt 0.1 W, G 23 dBi, T 1 ms, Fn 5 dB, L 6 dB) give about
  5 dB for 1 m^2 at 1 NM and 35 dB for 1000 m^2.
- Antenna (item 2): Gaussian one-way azimuth pattern ``exp(-4 ln2 theta^2 / theta3^2)``,
  squared for two way; 5.2 deg 3 dB width for an 18 in dome (unverified).
- Rain (item 9): one-way attenuation from ITU-R P.838 at 9.41 GHz (0.0093, 0.056, 0.33,
  1.44 dB/km at 1, 4, 16, 50 mm/h, interpolated log-log); volume backscatter
  ``eta = pi^5 |K|^2 Z / lambda^4`` with |K|^2 = 0.93 and ``Z = 200 R^1.6`` mm^6/m^3.

This module is the first part of the radar (issue 4): pure, vectorised functions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SPEED_OF_LIGHT_MPS = 299_792_458.0
KT0_DBM_PER_HZ = -174.0
NAUTICAL_MILE_M = 1852.0
RAIN_RATES_MM_PER_H = np.array([1.0, 4.0, 16.0, 50.0])
RAIN_ATTENUATION_DB_PER_KM = np.array([0.0093, 0.056, 0.33, 1.44])  # ITU-R P.838, 9.41 GHz, one way
WATER_K_SQUARED = 0.93


@dataclass(frozen=True)
class RadarLink:
    """Transmitter, antenna and receiver figures (defaults: REFERENCE.md section 3 item 1)."""

    frequency_hz: float = 9.41e9
    power_w: float = 0.1
    gain_dbi: float = 23.0
    sweep_s: float = 1e-3
    noise_figure_db: float = 5.0
    losses_db: float = 6.0

    @property
    def wavelength_m(self) -> float:
        return SPEED_OF_LIGHT_MPS / self.frequency_hz

    def snr_db(self, sigma_m2, range_m, propagation_factor_f4=1.0):
        """Single-sweep signal-to-noise ratio, dB, of targets of RCS sigma (m^2) at range R (m)."""
        g = 10.0 ** (self.gain_dbi / 10.0)
        kt0 = 10.0 ** ((KT0_DBM_PER_HZ - 30.0) / 10.0)  # W/Hz
        noise = kt0 * 10.0 ** (self.noise_figure_db / 10.0) * 10.0 ** (self.losses_db / 10.0)
        r = np.asarray(range_m, dtype=float)
        with np.errstate(divide="ignore"):
            snr = (self.power_w * g * g * self.wavelength_m**2 * np.asarray(sigma_m2, dtype=float) * self.sweep_s
                   * propagation_factor_f4) / ((4.0 * np.pi) ** 3 * r**4 * noise)
            return 10.0 * np.log10(snr)


def two_way_gain(off_axis_rad, beamwidth_rad: float):
    """Two-way Gaussian azimuth pattern (power, 1 on axis, 0.25 at the one-way 3 dB edge)."""
    theta = np.asarray(off_axis_rad, dtype=float)
    one_way = np.exp(-4.0 * np.log(2.0) * theta * theta / (beamwidth_rad * beamwidth_rad))
    return one_way * one_way


def rain_attenuation_db_per_km(rain_mm_per_h: float) -> float:
    """One-way specific attenuation of rain at 9.41 GHz, dB/km (ITU-R P.838 table, log-log)."""
    if rain_mm_per_h <= 0:
        return 0.0
    x, xp, fp = np.log(rain_mm_per_h), np.log(RAIN_RATES_MM_PER_H), np.log(RAIN_ATTENUATION_DB_PER_KM)
    i = int(np.clip(np.searchsorted(xp, x) - 1, 0, len(xp) - 2))  # power law of the nearest segment, also beyond the table
    slope = (fp[i + 1] - fp[i]) / (xp[i + 1] - xp[i])
    return float(np.exp(fp[i] + slope * (x - xp[i])))


def rain_reflectivity_m2_per_m3(rain_mm_per_h: float, wavelength_m: float = SPEED_OF_LIGHT_MPS / 9.41e9) -> float:
    """Volume backscatter eta of rain, m^2/m^3 (4 mm/h: about 5e-7)."""
    if rain_mm_per_h <= 0:
        return 0.0
    z_m6_per_m3 = 200.0 * rain_mm_per_h**1.6 * 1e-18  # mm^6/m^3 -> m^6/m^3
    return float(np.pi**5 * WATER_K_SQUARED * z_m6_per_m3 / wavelength_m**4)
