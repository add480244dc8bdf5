"""When AIS transponders transmit: ITU-R M.1371 reporting intervals, slots, channels, jitter.

docs/reference.md section 4. Class A position reports (types 1/3): at anchor or moored and under
3 kn every 3 min; 0-14 kn every 10 s (3 1/3 s while changing course); 14-23 kn every 6 s (2 s
while changing course); over 23 kn every 2 s. Static and voyage data (type 5) at start and
every 6 min. Class B "CS" (type 18): every 30 s above 2 kn, every 3 min at or below; static data
(type 24 parts A and B) every 6 min.

"Changing course" is taken as a rate of turn over :data:`TURNING_DEG_PER_MIN` (engineering
choice; ITU leaves the detection to the equipment).

The schedule follows the reporting rate as it changes: a report "phase" grows by
``dt / interval(t)`` and a report is due at each whole number. Each report is then moved by a
uniform jitter of up to :data:`JITTER_FRACTION` of its interval (SOTDMA picks a free slot in a
selection interval around the nominal time) and snapped to the 26.67 ms slot grid.
"""

from __future__ import annotations

import numpy as np

from groundfloor.ais import HELD_MAX_SOG_KN, HELD_REPORT_INTERVAL_S

__all__ = ["SLOT_S", "class_a_interval_s", "class_b_interval_s", "due_times", "TURNING_DEG_PER_MIN"]

SLOT_S = 60.0 / 2250.0  # one TDMA slot (2250 per minute per channel)
STATIC_INTERVAL_S = 360.0  # type 5 / type 24 every 6 min
TURNING_DEG_PER_MIN = 10.0  # "changing course" above this rate of turn (engineering choice)
JITTER_FRACTION = 0.1  # report times spread over +-10 % of the interval (SOTDMA selection interval)


def class_a_interval_s(sog_kn: np.ndarray, turning: np.ndarray, anchored: np.ndarray) -> np.ndarray:
    """Class A reporting interval, s, from speed over ground, changing course and nav status.

    Parameters
    ----------
    sog_kn : (n,) float
    turning : (n,) bool
        Changing course.
    anchored : (n,) bool
        At anchor or moored.

    Returns
    -------
    (n,) float
    """
    sog = np.asarray(sog_kn, dtype=float)
    turning = np.asarray(turning, dtype=bool)
    interval = np.where(sog > 23.0, 2.0,
                        np.where(sog > 14.0, np.where(turning, 2.0, 6.0), np.where(turning, 10.0 / 3.0, 10.0)))
    return np.where(np.asarray(anchored, dtype=bool) & (sog < HELD_MAX_SOG_KN), HELD_REPORT_INTERVAL_S, interval)


def class_b_interval_s(sog_kn: np.ndarray) -> np.ndarray:
    """Class B CS reporting interval, s: 30 s above 2 kn, 180 s at or below."""
    return np.where(np.asarray(sog_kn, dtype=float) > 2.0, 30.0, 180.0)


def due_times(grid_s: np.ndarray, interval_s: np.ndarray, rng: np.random.Generator, duration_s: float) -> np.ndarray:
    """Report times for an interval that varies along a time grid.

    Parameters
    ----------
    grid_s : (g,) float
        Uniform time grid covering the run (finer than the shortest interval), s.
    interval_s : (g,) float
        Reporting interval at each grid time, s.
    rng : numpy.random.Generator
        For the first report's phase and the jitter.
    duration_s : float

    Returns
    -------
    (m,) float
        Increasing report times on the slot grid within [0, duration_s).
    """
    dt = np.diff(grid_s)
    rate = 1.0 / interval_s
    phase = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * dt)]) + rng.uniform(0.0, 1.0)
    whole = np.floor(phase)
    k = np.flatnonzero(whole[1:] > whole[:-1])  # a whole number crossed in (grid[k], grid[k+1]]
    frac = (whole[k + 1] - phase[k]) / np.maximum(phase[k + 1] - phase[k], 1e-12)
    t = grid_s[k] + frac * dt[k]
    t = t + rng.uniform(-JITTER_FRACTION, JITTER_FRACTION, t.size) * interval_s[k]
    t = np.round(t / SLOT_S) * SLOT_S
    t = np.unique(t[(t >= 0.0) & (t < duration_s)])
    return t
