"""The land mask: which positions of the TDM's local frame lie on the recording's land.

As a real TDM masks with an ENC's land areas, the TDM masks with the land the recording carries
(``land.geojson``, :func:`tdm.recording.land.read_land`), never with the simulator's:

- **detections**: LiDAR points on land are dropped before clustering, and LiDAR clusters and radar
  plots whose position lies on land are dropped before tracking
  (:data:`DETECTION_MARGIN_M` around the land counts as land: a coast face's returns lie on the
  shoreline, a little either side of it);
- **output**: a target (or a sensor track) whose estimate lies on the land itself (no margin) at an
  output epoch is not reported at that epoch; its track goes on, and is reported again with the same
  id once its estimate is back at sea.

AIS reports are never masked: a ship's AIS position is at sea in any valid scenario.

The polygons are projected vertex by vertex into the frame (transverse Mercator about the own
ship's first fix, :mod:`tdm.frames`); an edge of a few hundred metres bends from its geodesic by
far less than a centimetre over a scene's few kilometres. Tests are vectorised
(:func:`shapely.contains_xy` on a prepared geometry).
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from tdm.detections import Detections
from tdm.frames import EnuFrame
from tdm.recording.land import ChartLand

__all__ = ["DETECTION_MARGIN_M", "LandMask", "ashore", "beam_margin_m", "drop_on_land", "on_chart_land"]

#: Band around the land that counts as land for detections, m: one range resolution cell of the radar
#: front end (2.5 m, :class:`tdm.frontend.radar_config.RadarFrontEndConfig`). Measured on a 10 s
#: recording of an 80 m x 50 m island 60 m off (tests/tdm/test_land.py's scene): masking the LiDAR's
#: points without a margin left 2 clusters 0.1-0.2 m at sea (points of the face at the shoreline, with
#: their noise; unmasked, its 99 clusters lay inland), with 0.5 m none; its radar plots lay 4.3-4.6 m inland. It
#: costs a ship only the outer 2.5 m of water along a shore (docs/tdm.md, "Land (chart) mask").
DETECTION_MARGIN_M = 2.5


class LandMask:
    """Land in the TDM's local frame, grown by a margin, as a vectorised point test.

    Parameters
    ----------
    land : ChartLand
        The recording's land (lon/lat polygons).
    frame : EnuFrame
        The TDM's local frame.
    margin_m : float
        Grow the land by this much, m (>= 0; 0: the land itself).
    """

    def __init__(self, land: ChartLand, frame: EnuFrame, margin_m: float = 0.0):
        if not margin_m >= 0.0:
            raise ValueError(f"land margin must be >= 0 m, not {margin_m!r}")
        self.margin_m = float(margin_m)
        self.geometry = self._projected(land, frame)
        if self.margin_m > 0.0:
            self.geometry = shapely.buffer(self.geometry, self.margin_m)
        shapely.prepare(self.geometry)

    @staticmethod
    def _projected(land: ChartLand, frame: EnuFrame) -> BaseGeometry:
        """The union of the land's polygons in ENU metres."""
        def to_enu(lonlat: np.ndarray) -> np.ndarray:
            east, north = frame.to_enu(lonlat[:, 1], lonlat[:, 0])
            return np.stack([east, north], axis=1)

        return shapely.union_all([shapely.transform(p, to_enu) for p in land.polygons])

    def __setstate__(self, state: dict) -> None:  # a copy in a worker process: prepare again
        self.__dict__.update(state)
        shapely.prepare(self.geometry)

    def contains(self, east_m, north_m) -> np.ndarray:
        """Whether each point (east, north), m, lies on the (grown) land, boundary included.

        Parameters
        ----------
        east_m, north_m : (N,) array_like
            ENU positions, metres.

        Returns
        -------
        (N,) bool
        """
        east, north = np.asarray(east_m, dtype=float), np.asarray(north_m, dtype=float)
        return np.asarray(shapely.intersects_xy(self.geometry, east, north), dtype=bool)


def beam_margin_m(range_m: np.ndarray, beam_fraction: float, beam_az_deg: float) -> np.ndarray:
    """(N,) how far from land a radar plot at each range may be the land's own echo, smeared by the beam, m.

    A coast face paints over the whole two-way beam as the antenna sweeps past it: its echo spreads
    ``beam_fraction`` of the -3 dB beamwidth either side of the face's bearing, ``range sin(fraction theta3)``
    across (beamwidth distortion: a radar cannot resolve what lies nearer the land than that; IMO
    MSC.192(79) states the resolution of a radar as its beamwidth and range resolution). 0 at the default
    fraction 0 (no margin).

    Parameters
    ----------
    range_m : (N,) float
        Ranges of the plots from the antenna, m.
    beam_fraction : float
        Fraction of the beamwidth either side (0.5: half the beam).
    beam_az_deg : float
        -3 dB one-way horizontal beamwidth, deg.
    """
    return np.asarray(range_m, dtype=float) * np.sin(np.radians(beam_fraction * beam_az_deg))


def drop_on_land(detections: Detections, mask: LandMask | None, beam_fraction: float = 0.0,
                 beam_az_deg: float = 0.0) -> Detections:
    """``detections`` without those whose position lies in ``mask`` (all of them when ``mask`` is None).

    With ``beam_fraction`` > 0 (radar plots), a detection is also dropped when it lies within
    :func:`beam_margin_m` of the mask: the land's echo smeared by the beam, not a target that can be told
    from it.
    """
    if mask is None or len(detections) == 0:
        return detections
    keep = ~ashore(mask, detections.position_m, detections.range_m, beam_fraction, beam_az_deg)
    return detections if keep.all() else detections.subset(keep)


def ashore(mask: LandMask, position_m: np.ndarray, range_m: np.ndarray, beam_fraction: float = 0.0,
           beam_az_deg: float = 0.0) -> np.ndarray:
    """(N,) bool: which detections at ``position_m`` (N, 2) (east, north, m) and ``range_m`` (N,) (m) lie in ``mask``
    or, with ``beam_fraction`` > 0, within :func:`beam_margin_m` of it (:func:`drop_on_land`)."""
    east, north = position_m[:, 0], position_m[:, 1]
    out = np.array(mask.contains(east, north), dtype=bool)
    if beam_fraction > 0.0 and not out.all():
        margin = beam_margin_m(range_m, beam_fraction, beam_az_deg)
        near = np.flatnonzero(~out & (margin > 0.0))
        if near.size:
            distance = shapely.distance(mask.geometry, shapely.points(east[near], north[near]))
            out[near[distance <= margin[near]]] = True
    return out


def on_chart_land(land: ChartLand | None, lat_deg, lon_deg) -> np.ndarray:
    """Whether each WGS84 position lies on the chart's land itself (boundary included), for the evaluation.

    Parameters
    ----------
    land : ChartLand or None
        The recording's land (None: no land, all False).
    lat_deg, lon_deg : (N,) array_like
        Positions, degrees.

    Returns
    -------
    (N,) bool
    """
    lat, lon = np.asarray(lat_deg, dtype=float), np.asarray(lon_deg, dtype=float)
    if land is None or not land.polygons or lat.size == 0:
        return np.zeros(lat.shape, dtype=bool)
    geometry = land.geometry()
    shapely.prepare(geometry)
    return np.asarray(shapely.intersects_xy(geometry, lon, lat), dtype=bool)
