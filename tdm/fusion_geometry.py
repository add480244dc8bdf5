"""Footprint and velocity tests of the fusion (:mod:`tdm.fusion`): whether two estimates may be one object.

Pure functions of (6,) states and (6, 6) covariances (:mod:`tdm.ekf`); :class:`tdm.fusion.Fuser` decides
with them which tracks are pieces of a target and which targets are one object.
"""

from __future__ import annotations

import math

import numpy as np

from tdm import ekf
from tdm.association import mahalanobis2

__all__ = ["FOOTPRINT_SIGMAS", "MERGE_SIGMAS", "MERGE_SPEED_MPS", "clearly_apart", "finite_or_inf", "inside_reference",
           "major_variance", "moves_apart"]

#: A track lies inside a target's footprint within its half length plus this many standard deviations
#: of the track's position (the radar beam smears a ship's ends by tens of metres at range).
FOOTPRINT_SIGMAS = 3.0
#: Two targets without AIS are one object only if their velocities differ by less than this, m/s.
MERGE_SPEED_MPS = 2.0
#: ... and a target without AIS inside an AIS ship's footprint is another object when its velocity differs from
#: the ship's by more than MERGE_SPEED_MPS plus this many standard deviations of its own velocity.
MERGE_SIGMAS = 3.0
#: Added to a velocity covariance before it is inverted (a still target's is singular: no course), (m/s)^2.
VELOCITY_FLOOR_M2PS2 = 1e-9
#: Relative rounding allowed for a closed-form 2 x 2 eigenvalue and a distance (far above their few ulp): a footprint
#: test closer to its edge than this is decided by the reference computation.
_EIGEN_TOLERANCE = 1e-12


def moves_apart(older: tuple[np.ndarray, np.ndarray], younger: tuple[np.ndarray, np.ndarray],
                 older_has_ais: bool) -> bool:
    """Whether the target without AIS moves otherwise than the AIS ship it lies inside: their velocity
    difference, less MERGE_SPEED_MPS along it, lies more than MERGE_SIGMAS standard deviations out in the
    target's own velocity covariance (a Mahalanobis distance: speed and heading errors mapped to east and
    north by the Jacobian of the velocity).

    A fragment of the AIS ship (a new radar track of its bow or stern) has an uncertain velocity and folds
    in; a ship crossing close by, tracked long enough to know its own velocity, does not (crossing_silent_ship,
    seeds 31-32: the silent crosser's target was folded into the overtaking ferry's as they passed, and its id
    went to the ferry). The covariance's shape matters: a coasting crosser's heading grows uncertain (30 deg on
    seed 35) while its speed stays known; a bound of speed error plus speed times heading error in every
    direction (this rule's first form) let it fold into a ferry 8 m/s away in velocity.

    Parameters
    ----------
    older, younger : tuple of (6,) and (6, 6) float
        The two targets' fused states and covariances (:mod:`tdm.ekf`).
    older_has_ais : bool
        Which of the two has the AIS track.
    """
    (x_ais, _), (x_other, p_other) = (older, younger) if older_has_ais else (younger, older)
    difference = ekf.velocity_en(x_ais) - ekf.velocity_en(x_other)
    size = float(np.hypot(*difference))
    if size <= MERGE_SPEED_MPS:
        return False
    beyond = difference * (1.0 - MERGE_SPEED_MPS / size)  # the difference less the margin, along it
    speed, course = float(x_other[ekf.U]), float(x_other[ekf.PSI])
    jacobian = np.array([[math.sin(course), speed * math.cos(course)],
                         [math.cos(course), -speed * math.sin(course)]])  # d(east, north) / d(U, PSI)
    index = [ekf.U, ekf.PSI]
    cov = jacobian @ p_other[np.ix_(index, index)] @ jacobian.T + VELOCITY_FLOOR_M2PS2 * np.eye(2)
    return float(beyond @ np.linalg.solve(cov, beyond)) > MERGE_SIGMAS**2


def major_variance(a: float, b: float, d: float) -> float:
    """The larger eigenvalue of the symmetric 2 x 2 ``[[a, b], [b, d]]`` in closed form: the variance along a position
    covariance's major axis, m^2 (:func:`clearly_apart` does the same on arrays)."""
    return 0.5 * (a + d) + math.hypot(0.5 * (a - d), b)


def inside(state, centre: np.ndarray, half_length_m: float) -> bool:
    """Whether the track's position lies within ``half_length_m`` plus FOOTPRINT_SIGMAS standard deviations (along
    its covariance's major axis) of ``centre``.

    Decided on Python floats with the 2 x 2 eigenvalue in closed form when the distance clears the radius by
    more than their rounding can move either (a generous bound); else as :func:`inside_reference`, so that
    every decision is the reference's (tests/tdm/test_fusion.py; :meth:`tdm.fusion.Fuser._inside`).
    """
    x, p = state
    a, b, d = float(p[0, 0]), float(p[1, 0]), float(p[1, 1])
    distance = math.hypot(float(x[0]) - float(centre[0]), float(x[1]) - float(centre[1]))
    largest = major_variance(a, b, d)
    if math.isfinite(largest + distance + half_length_m):
        radius = half_length_m + FOOTPRINT_SIGMAS * math.sqrt(max(largest, 0.0))
        # sqrt moves by at most sqrt of what the eigenvalue moves; both eigenvalues are within a few ulp of |P|
        slack = FOOTPRINT_SIGMAS * math.sqrt(_EIGEN_TOLERANCE * (abs(a) + abs(b) + abs(d))) \
            + _EIGEN_TOLERANCE * (distance + radius)
        if distance < radius - slack:
            return True
        if distance > radius + slack:
            return False
    return inside_reference(state, centre, half_length_m)


def within_reach(state, centre: np.ndarray, spread: np.ndarray, half_length_m: float, gate_chi2: float) -> bool:
    """Whether a track's position may be that of an object predicted to ``centre``: its distance from there, less
    ``half_length_m`` (the object's footprint), passes ``gate_chi2`` (chi-square, 2 dof) in the sum of the track's
    position covariance and the prediction's ``spread`` (its (6, 6) or (2, 2) covariance); False where either is
    not finite.

    Parameters
    ----------
    state : tuple of (6,) and (6, 6) float
        The track's state and covariance (east, north, m first).
    centre : (2,) or (6,) float
        The predicted position (east, north, m first).
    spread : (2, 2) or (6, 6) float
    half_length_m : float
    gate_chi2 : float
    """
    x, p = state
    d = np.asarray(x[:2], dtype=float) - np.asarray(centre[:2], dtype=float)
    distance = float(np.hypot(*d))
    beyond = d * max(0.0, 1.0 - half_length_m / distance) if distance > 0.0 else d
    cov = np.asarray(p, dtype=float)[:2, :2] + np.asarray(spread, dtype=float)[:2, :2]
    if not (np.all(np.isfinite(cov)) and np.all(np.isfinite(beyond))):
        return False
    return float(mahalanobis2(beyond, cov)) <= gate_chi2


def inside_reference(state, centre: np.ndarray, half_length_m: float) -> bool:
    """:func:`inside` in numpy operations (LAPACK's eigenvalue): the reference of its fast decision."""
    x, p = state
    sigma = np.sqrt(max(np.linalg.eigvalsh(p[:2, :2])[-1], 0.0))
    return bool(np.hypot(*(x[:2] - centre[:2])) <= half_length_m + FOOTPRINT_SIGMAS * sigma)


def clearly_apart(estimates: list[tuple[np.ndarray, np.ndarray]], half_lengths_m: list[float]) -> np.ndarray:
    """Which pairs of targets :meth:`Fuser._inside` certainly finds apart, all at once.

    Parameters
    ----------
    estimates : list of T tuples of (6,) and (6, 6) float
        The targets' fused states and covariances, oldest first.
    half_lengths_m : list of T float
        Their absorbing radii, m.

    Returns
    -------
    (T, T) bool
        ``[i, j]`` (i < j): target j lies outside the footprint of target i with radius ``max(half_i, half_j)``,
        clear of the edge by more than the rounding bound of :meth:`Fuser._inside` (no pair it would find inside;
        the pairs near the edge and the lower triangle are False: left to :meth:`Fuser._inside`).
    """
    n = len(estimates)
    if n < 2:
        return np.zeros((n, n), dtype=bool)
    xy = np.array([x[:2] for x, _ in estimates])
    cov = np.array([p[:2, :2] for _, p in estimates])
    a, b, d = cov[:, 0, 0], cov[:, 1, 0], cov[:, 1, 1]
    largest = 0.5 * (a + d) + np.hypot(0.5 * (a - d), b)
    half = np.asarray(half_lengths_m, dtype=float)
    radius = np.maximum(half[:, None], half[None, :]) + FOOTPRINT_SIGMAS * np.sqrt(np.maximum(largest, 0.0))[None, :]
    distance = np.hypot(xy[None, :, 0] - xy[:, None, 0], xy[None, :, 1] - xy[:, None, 1])
    slack = FOOTPRINT_SIGMAS * np.sqrt(_EIGEN_TOLERANCE * (np.abs(a) + np.abs(b) + np.abs(d)))[None, :] \
        + _EIGEN_TOLERANCE * (distance + radius)
    with np.errstate(invalid="ignore"):
        out = distance > radius + 2.0 * slack  # NaN: False
    return np.triu(out, 1)


def finite_or_inf(value: float) -> float:
    """``value``, or +inf where it is not finite (NaN sorts nowhere)."""
    return value if math.isfinite(value) else math.inf
