"""AIS positions moved from the ship's reference point to its hull's centre.

A transponder reports the position of its GNSS antenna, the "reference point for reported position", whose
distances from the bow, the stern, the port and the starboard side (A, B, C and D, metres) the ship's static data
give (messages 5, 19 and 24 part B, field "overall dimension/reference for position"; ITU-R M.1371-5, Annex 8).
It is seldom amidships: on a small vessel the antenna sits on the wheelhouse, on a cargo ship on the bridge aft.
The tracker, the fusion and the evaluation want the centre (docs/tdm.md, "Extended objects"), so each report is
moved there:

    centre = reference + (A - B) / 2 f + (C - D) / 2 l

with ``f`` the unit vector along the ship's heading and ``l`` the one to port (``f`` turned 90 deg anticlockwise).

- Only static data received at or before a report count (a log read afterwards must not see its future), the
  latest of them.
- The heading: the report's true heading; where it is not available (511), its COG when its SOG is at least
  :data:`COG_AS_HEADING_MIN_SOG_MPS`; else none.
- Known offset, no heading: the position stays at the reference point and the offset's length ``rho`` counts as
  noise, ``rho^2 / 2`` per axis (a point uniform on a circle of radius ``rho``).
- "Reference point not available" (A = C = 0 with B or D not 0: the dimensions without the point, as ITU-R
  M.1371-5 says to send them): it may lie anywhere on the hull, ``(B^2 + D^2) / 24`` per axis (a point uniform over
  the B x D hull outline, its along and across variances averaged, since the heading need not be known).
- A = B = C = D = 0 (not available) or no static data: the report is left as it is.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tdm.detections import AisReport
from tdm.hull import UNIFORM_VARIANCE_DIVISOR

__all__ = ["COG_AS_HEADING_MIN_SOG_MPS", "centre_offsets", "centred_reports"]

#: Lowest SOG at which a report's COG stands in for its missing true heading, m/s (about 2 kn: a ship making way
#: heads within a few degrees of its course, a drifting one need not).
COG_AS_HEADING_MIN_SOG_MPS = 1.0


def centre_offsets(heading_deg: np.ndarray, cog_deg: np.ndarray, sog_mps: np.ndarray, to_bow_m: np.ndarray,
                   to_stern_m: np.ndarray, to_port_m: np.ndarray, to_starboard_m: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """From each report's reference point to its hull's centre (module docstring).

    Parameters
    ----------
    heading_deg, cog_deg : (K,) float
        True heading and course over ground, compass deg (NaN: not available).
    sog_mps : (K,) float
        Speed over ground, m/s (NaN: not available).
    to_bow_m, to_stern_m, to_port_m, to_starboard_m : (K,) float
        Dimensions A, B, C and D, m, of the static data in force at each report (NaN: none received yet).

    Returns
    -------
    offset_m : (K, 2) float
        East and north, m, to add to each reported position (0 where it is not moved).
    extra_var_m2 : (K,) float
        Variance per axis, m^2, of what is not known of the reference point (0 where nothing).
    """
    a, b, c, d = (np.asarray(v, dtype=float) for v in (to_bow_m, to_stern_m, to_port_m, to_starboard_m))
    with np.errstate(invalid="ignore"):
        given = np.isfinite(a + b + c + d)
        point_unknown = given & (a == 0.0) & (c == 0.0) & ((b > 0.0) | (d > 0.0))
        point_known = given & ~point_unknown
        forward_m = np.where(point_known & (a + b > 0.0), (a - b) / 2.0, 0.0)
        port_m = np.where(point_known & (c + d > 0.0), (c - d) / 2.0, 0.0)
        cog_ok = np.isfinite(np.asarray(cog_deg, dtype=float)) \
            & (np.asarray(sog_mps, dtype=float) >= COG_AS_HEADING_MIN_SOG_MPS)
    heading = np.where(np.isfinite(heading_deg), heading_deg, np.where(cog_ok, cog_deg, np.nan))
    psi = np.radians(heading)
    along = np.stack([np.sin(psi), np.cos(psi)], axis=-1)  # compass heading -> (east, north)
    to_port = np.stack([-along[:, 1], along[:, 0]], axis=-1)
    steered = np.isfinite(heading)
    offset_m = np.where(steered[:, None], forward_m[:, None] * along + port_m[:, None] * to_port, 0.0)
    extra_var_m2 = np.where(steered, 0.0, (forward_m ** 2 + port_m ** 2) / 2.0)
    hull_var_m2 = np.where(point_unknown,
                           (np.nan_to_num(b) ** 2 + np.nan_to_num(d) ** 2) / UNIFORM_VARIANCE_DIVISOR / 2.0, 0.0)
    return offset_m, extra_var_m2 + hull_var_m2


def centred_reports(reports: list[AisReport],
                    references: dict[int, list[tuple[float, float, float, float, float]]]) -> list[AisReport]:
    """``reports`` with each position moved to its ship's hull centre (module docstring).

    Parameters
    ----------
    reports : list of AisReport
        Position reports, any order.
    references : dict of int to list of (t_s, A, B, C, D)
        Per MMSI, each static message's receive time (s since the recording's start) and its dimensions A-D (m),
        in the order received.

    Returns
    -------
    list of AisReport
        The same reports, in the same order; those moved or made less certain replaced
        (``position_m``, ``centre_offset_m`` and ``position_extra_var_m2``).
    """
    if not reports or not references:
        return reports
    mmsi = np.array([r.mmsi for r in reports], dtype=np.int64)
    t_s = np.array([r.time_s for r in reports], dtype=float)
    dims = np.full((len(reports), 4), np.nan)
    for ship, history in references.items():  # per ship, its static messages against its reports
        at = np.flatnonzero(mmsi == ship)
        if at.size == 0 or not history:
            continue
        table = np.array(sorted(history, key=lambda row: row[0]), dtype=float).reshape(-1, 5)
        last = np.searchsorted(table[:, 0], t_s[at], side="right") - 1
        dims[at[last >= 0]] = table[last[last >= 0], 1:]
    offset_m, extra_var_m2 = centre_offsets(np.array([r.heading_deg for r in reports], dtype=float),
                                            np.array([r.cog_deg for r in reports], dtype=float),
                                            np.array([r.sog_mps for r in reports], dtype=float), *dims.T)
    out = list(reports)
    moved = np.any(offset_m != 0.0, axis=1)
    for k in np.flatnonzero(moved | (extra_var_m2 > 0.0)):
        out[k] = replace(reports[k], position_m=reports[k].position_m + offset_m[k],
                         position_extra_var_m2=reports[k].position_extra_var_m2 + float(extra_var_m2[k]),
                         centre_offset_m=offset_m[k].copy() if moved[k] else None)
    return out
