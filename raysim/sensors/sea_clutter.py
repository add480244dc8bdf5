"""Sea clutter of a marine X-band radar: geometry, mean reflectivity and amplitude statistics.

Formulas and coefficients from REFERENCE.md section 3, items 4, 7 and 8:

- 4/3-earth geometry: effective radius ``re = 4/3 x 6371 km``; radar horizon
  ``sqrt(2 re h)``; grazing angle ``psi = asin(h/r + h^2/(2 re r) - r/(2 re))``.
- NRL mean reflectivity (Gregers-Hansen & Mital 2012; scivision
  nrl-radar-sea-clutter ``NRL_SigmaSea.m``), psi in degrees, f in GHz, SS = Douglas
  sea state::

      s0_dB = c1 + c2 log10(sin psi) + (27.5 + c3 psi) log10(f) / (1 + 0.95 psi)
              + c4 (SS + 1)^(1 / (2 + 0.085 psi + 0.033 SS)) + c5 psi^2

- Compound K statistics (Ward et al.): intensity = texture x speckle, texture Gamma
  of shape ``nu`` and mean 1, speckle exponential; ``log10 nu = (2/3) log10(psi_deg)
  + (5/8) log10(Ac) - k_pol - cos(2 theta_sw) / 3``, clamped to [0.1, 20].
- Texture range correlation length ``(pi/2)(W^2/g) sqrt(3 cos^2(Aw) + 1)`` with the
  wind speeds W of REFERENCE.md for sea states 1..6.

This module is the first part of the radar (issue 4): pure, vectorised functions.
"""

from __future__ import annotations

import numpy as np

EARTH_RADIUS_M = 6_371_000.0
EFFECTIVE_EARTH_RADIUS_M = 4.0 / 3.0 * EARTH_RADIUS_M  # standard refraction, 8495 km
GRAVITY_MPS2 = 9.81

#: NRL model coefficients (c1, c2, c3, c4, c5) by polarisation (REFERENCE.md section 3 item 7).
NRL_COEFFICIENTS = {
    "HH": (-73.0, 20.781, 7.351, 25.65, 0.0054),
    "VV": (-50.796, 25.93, 0.7093, 21.588, 0.00211),
}
#: Ward's polarisation term k_pol (REFERENCE.md section 3 item 8).
K_POL = {"VV": 1.39, "HH": 2.09}
K_SHAPE_RANGE = (0.1, 20.0)
#: Wind speed W (m/s) for the texture correlation length, Douglas sea states 1..6 (REFERENCE.md).
TEXTURE_WIND_MPS = (2.5, 4.5, 6.0, 8.5, 11.0, 14.0)


def radar_horizon_m(antenna_height_m: float) -> float:
    """Distance to the radar horizon over a 4/3 earth, m (7.1 km for a 3 m antenna)."""
    return float(np.sqrt(2.0 * EFFECTIVE_EARTH_RADIUS_M * antenna_height_m))


def curvature_drop_m(distance_m):
    """How far the sea surface lies below the tangent plane at horizontal distance d: d^2 / (2 re)."""
    distance_m = np.asarray(distance_m, dtype=float)
    return distance_m * distance_m / (2.0 * EFFECTIVE_EARTH_RADIUS_M)


def grazing_angle_deg(antenna_height_m: float, range_m):
    """Grazing angle of the sea at slant range r from an antenna h above it, degrees (nan past the horizon)."""
    r = np.asarray(range_m, dtype=float)
    h = float(antenna_height_m)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = h / r + h * h / (2.0 * EFFECTIVE_EARTH_RADIUS_M * r) - r / (2.0 * EFFECTIVE_EARTH_RADIUS_M)
    return np.degrees(np.arcsin(np.where(s > 0.0, np.minimum(s, 1.0), np.nan)))


def nrl_sigma0_db(grazing_deg, frequency_ghz: float, sea_state: float, polarisation: str = "HH"):
    """NRL mean sea-clutter reflectivity sigma0, dB (m^2/m^2), for grazing angles in degrees."""
    c1, c2, c3, c4, c5 = NRL_COEFFICIENTS[polarisation]
    psi = np.asarray(grazing_deg, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return (c1 + c2 * np.log10(np.sin(np.radians(psi)))
                + (27.5 + c3 * psi) * np.log10(frequency_ghz) / (1.0 + 0.95 * psi)
                + c4 * (sea_state + 1.0) ** (1.0 / (2.0 + 0.085 * psi + 0.033 * sea_state))
                + c5 * psi * psi)


def cell_area_m2(range_m, azimuth_beamwidth_rad: float, range_resolution_m: float, grazing_deg):
    """Area of a clutter resolution cell at low grazing angles, ``R theta dR sec(psi)``, m^2."""
    return np.asarray(range_m, dtype=float) * azimuth_beamwidth_rad * range_resolution_m / np.cos(np.radians(grazing_deg))


def k_shape(grazing_deg, cell_area, polarisation: str = "HH", angle_to_swell_rad: float = 0.0):
    """Ward's K-distribution shape parameter nu, clamped to [0.1, 20]."""
    psi = np.maximum(np.asarray(grazing_deg, dtype=float), 1e-6)
    log_nu = (2.0 / 3.0) * np.log10(psi) + (5.0 / 8.0) * np.log10(cell_area) - K_POL[polarisation] - np.cos(2.0 * angle_to_swell_rad) / 3.0
    return np.clip(10.0 ** log_nu, *K_SHAPE_RANGE)


def texture_correlation_length_m(sea_state: int, look_to_wind_rad: float = 0.0) -> float:
    """Range correlation length of the clutter texture, m (0 for a glassy sea)."""
    if sea_state <= 0:
        return 0.0
    wind = TEXTURE_WIND_MPS[min(int(sea_state), 6) - 1]
    return float(np.pi / 2.0 * wind**2 / GRAVITY_MPS2 * np.sqrt(3.0 * np.cos(look_to_wind_rad) ** 2 + 1.0))


def k_distributed_intensity(mean, shape, rng: np.random.Generator, texture=None):
    """Clutter intensities with the given means and K shapes: Gamma(shape, 1/shape) texture x Exp(1) speckle.

    Parameters
    ----------
    mean, shape : array_like
        Mean intensity and K shape nu per sample (broadcast together).
    rng : numpy.random.Generator
    texture : array_like, optional
        A texture to use (correlated in range and time by the caller); drawn independently if None.
    """
    mean, shape = np.broadcast_arrays(np.asarray(mean, dtype=float), np.asarray(shape, dtype=float))
    if texture is None:
        texture = rng.gamma(shape, 1.0 / shape)
    speckle = rng.exponential(1.0, size=mean.shape)
    return mean * texture * speckle
