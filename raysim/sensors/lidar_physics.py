"""LiDAR physics at 905 nm: link budget, weather, reflectivity byte, echoes.

All of it is vectorised over firings; every constant is a parameter with its source.

- Received power of a diffuse echo, relative: ``P = rho cos(theta) T^2 / R^2``
  (Lambertian target filling the beam, range-squared law) with the two-way
  atmospheric transmission ``T^2 = exp(-2 alpha R)``. An echo is detected when
  ``P >= rho_det / (100 m)^2``: a target of apparent reflectance
  ``detection_reflectance`` is just seen at 100 m in clear air (the HDL-32E's
  rated range; the reflectance behind that rating is not published -- unverified).
- Extinction ``alpha`` (1/m): fog by Koschmieder, ``3.912 / V`` (V = visibility,
  m); rain ``1.076 R^0.67`` dB/km (R in mm/h; free-space-optics rain model,
  Carbonneau & Wisely 1998 as quoted in the FSO literature -- unverified at 905 nm).
- Weather also produces false echoes near the sensor (backscatter of drops): a ray
  gets one with probability ``1 - exp(-alpha L)`` (L = 10 m window), at a range
  drawn from an exponential of mean 3 m beyond the minimum range, with backscatter
  reflectance 0.02 (engineering values, unverified).
- Reflectivity byte (firmware >= 2.0, docs/reference.md section 2): diffuse surfaces
  0..100 = 100 x the apparent reflectance ``rho cos(theta)``; retro-reflectors
  101..255, growing with ``cos(theta)``.
- Echoes of a firing (:func:`select_echoes`): candidates closer than :data:`ECHO_MERGE_M` form one
  echo; the strongest, the last and the second-strongest echo are picked. Dual-return mode reports
  the last and the strongest, or, when the strongest is also the last, the last and the
  second-strongest (Velodyne HDL-32E user manual, dual return mode: :func:`dual_pick`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

REFERENCE_RANGE_M = 100.0
KOSCHMIEDER = 3.912  # ln(50): 2 % contrast threshold
RAIN_DB_PER_KM_COEFF = 1.076
RAIN_DB_PER_KM_EXPONENT = 0.67
DB_PER_KM_TO_PER_M = np.log(10.0) / 10.0 / 1000.0
FALSE_ECHO_WINDOW_M = 10.0
FALSE_ECHO_MEAN_RANGE_M = 3.0
FALSE_ECHO_REFLECTANCE = 0.02
ECHO_MERGE_M = 0.3  # sub-ray hits closer than this in range form one echo (about the pulse length)


def extinction_per_m(fog_visibility_m: float | None, rain_mm_per_h: float) -> float:
    """One-way atmospheric extinction coefficient at 905 nm, 1/m."""
    alpha = 0.0
    if fog_visibility_m is not None:
        alpha += KOSCHMIEDER / fog_visibility_m
    if rain_mm_per_h > 0:
        alpha += RAIN_DB_PER_KM_COEFF * rain_mm_per_h**RAIN_DB_PER_KM_EXPONENT * DB_PER_KM_TO_PER_M
    return alpha


def echo_power(apparent_reflectance: np.ndarray, range_m: np.ndarray, alpha_per_m: float) -> np.ndarray:
    """Relative received power ``rho_app exp(-2 alpha R) / R^2`` (same shape as the inputs)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return apparent_reflectance * np.exp(-2.0 * alpha_per_m * range_m) / (range_m * range_m)


def detection_threshold(detection_reflectance: float) -> float:
    """Relative power of the weakest detectable echo."""
    return detection_reflectance / REFERENCE_RANGE_M**2


def reflectivity_byte(reflectance: np.ndarray, cos_incidence: np.ndarray, retro: np.ndarray) -> np.ndarray:
    """HDL-32E calibrated reflectivity byte (uint8) per echo."""
    diffuse = np.clip(np.round(100.0 * reflectance * cos_incidence), 1, 100)
    if not np.any(retro):  # (the usual case: the retro-reflective values would all be discarded)
        return np.broadcast_to(diffuse, np.broadcast_shapes(np.shape(diffuse), np.shape(retro))).astype(np.uint8)
    retro_value = 101 + np.round(154.0 * np.clip(cos_incidence, 0.0, 1.0))
    return np.where(retro, retro_value, diffuse).astype(np.uint8)


class Echoes(NamedTuple):
    """The echoes picked from each firing's candidates (:func:`select_echoes`).

    Attributes
    ----------
    strongest, last, second : (N,) int64
        Index of the representative candidate of the strongest, the last and the
        second-strongest detected echo group; -1 where there is none (``second``: fewer than
        two detected groups).
    group_range : (N, E) float64
        Power-weighted mean range of each candidate's group, m; inf where no candidate.
    group : (N, E) int64
        Group id of each candidate (two picks are one echo when their ids agree).
    """

    strongest: np.ndarray
    last: np.ndarray
    second: np.ndarray
    group_range: np.ndarray
    group: np.ndarray


def select_echoes(range_m: np.ndarray, power: np.ndarray, threshold: float) -> Echoes:
    """Group candidate echoes of each firing and pick the strongest, the last and the second-strongest.

    Parameters
    ----------
    range_m : (N, E) float64
        Candidate ranges (sub-rays and false echoes); inf where none.
    power : (N, E) float64
        Their relative powers.
    threshold : float
        Detection threshold on a group's summed power.

    Returns
    -------
    Echoes
        ``strongest``, ``last``, ``second`` (N,) candidate indices (-1: none), ``group_range``
        (N, E) m and ``group`` (N, E) ids.
    """
    n, e = range_m.shape
    if e == 1:
        detected = np.isfinite(range_m[:, 0]) & (power[:, 0] >= threshold)
        index = np.where(detected, 0, -1)
        return Echoes(index, index.copy(), np.full(n, -1, np.int64), range_m.copy(), np.zeros((n, 1), np.int64))
    finite = np.isfinite(range_m)
    p = np.where(finite, power, 0.0)
    r = np.where(finite, range_m, 0.0)
    # groups: candidates sorted by range, a new group wherever the gap to the previous exceeds the merge
    # distance (so a stretched echo from an oblique surface stays one echo)
    order = np.argsort(np.where(finite, range_m, np.inf), axis=1)
    r_sorted = np.take_along_axis(range_m, order, axis=1)
    with np.errstate(invalid="ignore"):
        gaps = ~(np.diff(r_sorted, axis=1) < ECHO_MERGE_M)
    gid_sorted = np.concatenate([np.zeros((n, 1), np.int64), np.cumsum(gaps, axis=1)], axis=1)
    gid = np.empty_like(gid_sorted)
    np.put_along_axis(gid, order, gid_sorted, axis=1)
    same = (gid[:, :, None] == gid[:, None, :]) & finite[:, :, None] & finite[:, None, :]
    group_power = np.einsum("nef,nf->ne", same, p)
    with np.errstate(invalid="ignore", divide="ignore"):
        group_range = np.einsum("nef,nf->ne", same, p * r) / group_power
    detected = finite & (group_power >= threshold)
    strongest = np.argmax(np.where(detected, group_power, -1.0), axis=1)
    last = np.argmax(np.where(detected, r, -1.0), axis=1)
    anything = detected.any(axis=1)
    # the second-strongest: the strongest of the detected groups other than the strongest's
    other = detected & (gid != np.take_along_axis(gid, strongest[:, None], axis=1))
    second = np.argmax(np.where(other, group_power, -1.0), axis=1)
    return Echoes(np.where(anything, strongest, -1), np.where(anything, last, -1),
                  np.where(other.any(axis=1), second, -1), np.where(finite, group_range, np.inf), gid)


def dual_pick(echoes: Echoes) -> np.ndarray:
    """The echo of the dual-return mode's odd (strongest) block, (N,) candidate index or -1.

    The HDL-32E reports the last echo in the even block and the strongest in the odd one; "if
    the strongest return is also the last return, the second-strongest return is reported"
    (Velodyne HDL-32E user manual, dual return mode). With a single echo this is the last echo
    itself (both blocks carry it).
    """
    rows = np.arange(echoes.last.shape[0])
    strongest_is_last = (echoes.group[rows, np.maximum(echoes.strongest, 0)]
                         == echoes.group[rows, np.maximum(echoes.last, 0)])
    return np.where(strongest_is_last & (echoes.second >= 0), echoes.second, echoes.strongest)


def sub_ray_offsets(count: int, divergence_rad: float) -> np.ndarray:
    """(K, 2) angular offsets (rad) of the sub-rays sampling a beam's divergence cone.

    1: the axis; 7: the axis and a ring of 6 at half the divergence angle... scaled so the
    rings sit at 1/3 and 2/3 of the cone's radius for 19 (hexagonal sampling).
    """
    if count == 1:
        return np.zeros((1, 2))
    half = divergence_rad / 2.0
    rings = [(0.0, 1)]
    if count == 7:
        rings.append((0.6 * half, 6))
    else:  # 19
        rings += [(0.35 * half, 6), (0.75 * half, 12)]
    offsets = []
    for radius, m in rings:
        angles = 2 * np.pi * np.arange(m) / m
        offsets.append(np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1))
    return np.concatenate(offsets)
