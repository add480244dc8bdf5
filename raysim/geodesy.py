"""Latitude/longitude <-> local metres about the scenario origin (pyproj).

The local frame is a transverse Mercator projection centred on the origin
(scale factor 1, WGS84), which docs/reference.md section 1 allows as the local ENU
frame: x east, y north, metres, exact in both directions. Within the 50 km a
scenario may span, grid north differs from true north by the meridian
convergence ``dlon * sin(lat)`` (0.015 deg at 1 km east of 59.4 N); raysim
ignores it (headings are taken as grid headings). Heights: the scene is a flat
sea at z = 0; earth curvature enters the radar model explicitly (4/3 earth).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from pyproj import Transformer


@lru_cache(maxsize=32)
def _transformers(lat0: float, lon0: float) -> tuple[Transformer, Transformer]:
    proj = f"+proj=tmerc +lat_0={lat0!r} +lon_0={lon0!r} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs"
    forward = Transformer.from_crs("EPSG:4326", proj, always_xy=True)
    inverse = Transformer.from_crs(proj, "EPSG:4326", always_xy=True)
    return forward, inverse


class LocalFrame:
    """Local metric frame about an origin.

    Parameters
    ----------
    lat0_deg, lon0_deg : float
        Origin latitude and longitude, degrees (WGS84).
    """

    def __init__(self, lat0_deg: float, lon0_deg: float):
        self.lat0_deg = float(lat0_deg)
        self.lon0_deg = float(lon0_deg)
        self._forward, self._inverse = _transformers(self.lat0_deg, self.lon0_deg)

    def to_local(self, lat_deg, lon_deg) -> tuple[np.ndarray, np.ndarray]:
        """(x east, y north) in metres, arrays of the inputs' shape, from lat/lon in degrees."""
        x, y = self._forward.transform(np.asarray(lon_deg, dtype=float), np.asarray(lat_deg, dtype=float))
        return np.asarray(x, dtype=float), np.asarray(y, dtype=float)

    def to_geodetic(self, x_m, y_m) -> tuple[np.ndarray, np.ndarray]:
        """(lat, lon) in degrees from local (x east, y north) metres."""
        lon, lat = self._inverse.transform(np.asarray(x_m, dtype=float), np.asarray(y_m, dtype=float))
        return np.asarray(lat, dtype=float), np.asarray(lon, dtype=float)
