"""Latitude/longitude <-> local metres about the scenario origin (pyproj).

The local frame is a transverse Mercator projection centred on the origin
(scale factor 1, WGS84), which docs/reference.md section 1 allows as the local ENU
frame: x east, y north, metres, exact in both directions. Within the 50 km a
scenario may span, grid north differs from true north by the meridian
convergence ``dlon * sin(lat)`` (0.015 deg at 1 km east of 59.4 N); raysim
ignores it (headings are taken as grid headings). Heights: the scene is a flat
sea at z = 0; earth curvature enters the radar model explicitly (4/3 earth).

:class:`LocalFrame` is :class:`groundfloor.frames.LocalFrame` (the TDM's ``EnuFrame``).
"""

from __future__ import annotations

from groundfloor.frames import LocalFrame  # noqa: F401 (the frame, shared with the TDM)
