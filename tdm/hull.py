"""Where on a ship's hull a sensor's track may lie: the covariance of a point uniform over the hull
(:class:`tdm.fusion.FusionConfig` ``weigh_hull``)."""

from __future__ import annotations

import math

import numpy as np

from tdm import ekf

__all__ = ["BEAM_PER_LENGTH", "UNIFORM_VARIANCE_DIVISOR", "hull_covariance"]

#: Variance of a uniform error over a width w is w^2 / 12.
UNIFORM_VARIANCE_DIVISOR = 12.0
#: Beam of a ship whose AIS gives its length only, as a fraction of the length (a length-to-beam of 6, a typical
#: merchant ship's).
BEAM_PER_LENGTH = 1.0 / 6.0


def hull_covariance(length_m: float, beam_m: float, x: np.ndarray, p: np.ndarray, known_sigmas: float = 2.0
                    ) -> np.ndarray:
    """Covariance of a point uniform over a ship's hull (where on it a radar track may lie).

    Parameters
    ----------
    length_m, beam_m : float
        The ship's length and beam (AIS static data), m; a beam not known (NaN) is taken as
        :data:`BEAM_PER_LENGTH` of the length.
    x : (6,) float
        The ship's state (:mod:`tdm.ekf`): its course ``x[PSI]`` (rad from north) and speed ``x[U]`` (m/s).
    p : (6, 6) float
        Its covariance.
    known_sigmas : float
        The course counts as known when the speed exceeds this many of its standard deviations.

    Returns
    -------
    (2, 2) float
        East-north covariance, m^2: ``L^2 / 12`` along the course and ``B^2 / 12`` across it (a uniform
        error over a width w has variance w^2 / 12); while the course is unknown, their mean both ways.
    """
    beam_m = beam_m if math.isfinite(beam_m) else BEAM_PER_LENGTH * length_m
    along, across = length_m ** 2 / UNIFORM_VARIANCE_DIVISOR, beam_m ** 2 / UNIFORM_VARIANCE_DIVISOR
    if abs(float(x[ekf.U])) <= known_sigmas * math.sqrt(max(float(p[ekf.U, ekf.U]), 0.0)):
        return 0.5 * (along + across) * np.eye(2)
    h = np.array([math.sin(float(x[ekf.PSI])), math.cos(float(x[ekf.PSI]))])  # course, unit (east, north)
    return across * np.eye(2) + (along - across) * np.outer(h, h)
