"""The radar's point-spread: the antenna pattern over spokes and the range impulse response along range.

:func:`antenna_pattern` and :func:`range_kernel` build, from a renderer's :class:`RadarParams`, the two
kernels the coherent target sum (:mod:`raysim.sensors.radar_targets`) is convolved with.
"""

from __future__ import annotations

import math

import numpy as np

from raysim.sensors import radar_physics as phys

__all__ = ["GaussianPattern", "antenna_pattern", "range_kernel"]

#: Full width at half maximum of a Gaussian in standard deviations, 2 sqrt(2 ln 2).
FWHM_PER_SIGMA = 2.3548
#: Half-length of the Gaussian range kernel in standard deviations.
GAUSS_HALF_SIGMAS = 5.0


class GaussianPattern:
    """A sidelobe-free Gaussian beam (the model before issue 19; kept for comparison).

    One-way power ``exp(-4 ln2 theta^2 / theta3^2)``, so the one-way voltage is its square root.
    """

    def __init__(self, beam_az_deg: float, beam_el_deg: float):
        self.beam_az_deg, self.beam_el_deg = beam_az_deg, beam_el_deg

    @staticmethod
    def _voltage(theta_deg, width_deg: float) -> np.ndarray:
        t = np.asarray(theta_deg, dtype=float)
        return np.exp(-2.0 * math.log(2.0) * t * t / (width_deg * width_deg))

    def horizontal_voltage(self, theta_deg) -> np.ndarray:
        """One-way voltage (complex, peak 1) at azimuth offsets, deg."""
        t = (np.asarray(theta_deg, dtype=float) + 180.0) % 360.0 - 180.0
        return self._voltage(t, self.beam_az_deg).astype(complex)

    def vertical_voltage(self, el_deg) -> np.ndarray:
        """One-way voltage (peak 1) at elevations in the antenna frame, deg."""
        return self._voltage(el_deg, self.beam_el_deg)

    def spoke_kernel(self, spokes: int) -> np.ndarray:
        """(S,) complex two-way voltage at circular spoke offsets 0..S-1."""
        j = np.arange(spokes)
        theta = np.where(j > spokes // 2, j - spokes, j) * (360.0 / spokes)
        return self.horizontal_voltage(theta) ** 2


def antenna_pattern(params, seed: int):
    """The antenna of ``params`` (:class:`raysim.sensors.radar.RadarParams`): aperture pattern or Gaussian."""
    if getattr(params, "sidelobe_db", None) is None:
        return GaussianPattern(params.beam_az_deg, params.beam_el_deg)
    from raysim.sensors.radar_antenna import AntennaPattern

    return AntennaPattern(params.beam_az_deg, params.beam_el_deg, params.sidelobe_db, seed, params.f_ghz)


def range_kernel(params, dr_m: float) -> np.ndarray:
    """(L,) complex range impulse response (voltage, peak 1, centred, odd length) at the sample spacing ``dr_m``.

    A Gaussian whose power has the range resolution as its FWHM (REF 3.3) unless the receiver model
    gives its own (:mod:`raysim.sensors.radar_receiver`).
    """
    sigma_v = params.range_resolution_m / FWHM_PER_SIGMA * math.sqrt(2.0) / dr_m  # voltage sigma, samples
    half = max(1, int(math.ceil(GAUSS_HALF_SIGMAS * sigma_v)))
    x = np.arange(-half, half + 1)
    return np.exp(-0.5 * (x / max(sigma_v, 1e-6)) ** 2).astype(complex)


_ = phys  # the sources of the figures are in radar_physics
