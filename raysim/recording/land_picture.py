"""The recording's land (``land.geojson``) for its pictures: polygons in the local frame, clipped.

``map.png`` fills them and the LiDAR bird's-eye views outline them. Both read the chart the
recording carries (:data:`groundfloor.recording.LAND`, written from the scenario's GeoJSON files),
so a picture shows the same land a TDM masks with.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
from shapely.geometry import LineString, Polygon, box, shape

from groundfloor.frames import LocalFrame
from groundfloor.recording import LAND

__all__ = ["LAND_COLOURS", "LandOutline", "clip_polygons", "clip_shoreline", "land_extent", "read_land",
           "recording_frame"]

#: Fill colours of land on ``map.png`` by material (RGB): earth tones for rock, vegetation and sand,
#: a light grey-brown for concrete quays and piers.
LAND_COLOURS: dict[str, tuple[int, int, int]] = {"rock": (120, 110, 95), "vegetation": (80, 110, 60),
                                                 "sand": (200, 180, 120), "concrete": (165, 160, 150)}


@dataclass(frozen=True)
class LandOutline:
    """One land polygon of the recording in the local frame.

    Attributes
    ----------
    polygon : shapely.geometry.Polygon
        x east, y north, metres; holes kept.
    material : str
        Its material (``rock``, ``vegetation``, ``sand`` or ``concrete``).
    name : str
        The land object's name.
    """

    polygon: Polygon
    material: str
    name: str


def recording_frame(recording: Path) -> LocalFrame | None:
    """The local frame of a recording, from the origin in its ``scenario.yaml`` (None without one)."""
    path = Path(recording) / "scenario.yaml"
    if not path.is_file():
        return None
    origin = (yaml.safe_load(path.read_text(encoding="utf-8")) or {}).get("origin")
    if not isinstance(origin, dict) or "lat" not in origin or "lon" not in origin:
        return None
    return LocalFrame(float(origin["lat"]), float(origin["lon"]))


def _to_local(polygon: Polygon, frame: LocalFrame) -> Polygon:
    """A lon/lat polygon in local east/north metres (holes kept)."""

    def ring(coords) -> np.ndarray:
        lonlat = np.asarray(coords, dtype=np.float64)[:, :2]
        x_m, y_m = frame.to_local(lonlat[:, 1], lonlat[:, 0])
        return np.column_stack([x_m, y_m])

    return Polygon(ring(polygon.exterior.coords), [ring(r.coords) for r in polygon.interiors])


def read_land(recording: Path, frame: LocalFrame | None = None) -> list[LandOutline]:
    """The land polygons of ``recording/land.geojson`` in the local frame (empty without land).

    Parameters
    ----------
    recording : Path
        Recording directory.
    frame : LocalFrame, optional
        The recording's local frame; default :func:`recording_frame`.

    Returns
    -------
    list of LandOutline
        In file order; a MultiPolygon gives one per polygon.
    """
    path = Path(recording) / LAND
    frame = frame or recording_frame(recording)
    if not path.is_file() or frame is None:
        return []
    outlines = []
    for feature in json.loads(path.read_text(encoding="utf-8")).get("features", []):
        properties = feature.get("properties") or {}
        geometry = shape(feature["geometry"])
        for polygon in getattr(geometry, "geoms", [geometry]):
            outlines.append(LandOutline(_to_local(polygon, frame), str(properties.get("material", "rock")),
                                        str(properties.get("name", ""))))
    return outlines


def clip_polygons(polygon: Polygon, x0_m: float, y0_m: float, x1_m: float, y1_m: float) -> list[Polygon]:
    """The parts of ``polygon`` inside the box [x0, x1] x [y0, y1] (metres); empty when none."""
    clipped = polygon.intersection(box(x0_m, y0_m, x1_m, y1_m))
    parts = getattr(clipped, "geoms", [clipped])
    return [p for p in parts if isinstance(p, Polygon) and not p.is_empty]


def clip_shoreline(polygon: Polygon, x0_m: float, y0_m: float, x1_m: float, y1_m: float) -> list[np.ndarray]:
    """The shoreline (every ring of ``polygon``) inside the box [x0, x1] x [y0, y1] as (N, 2) polylines, metres."""
    area = box(x0_m, y0_m, x1_m, y1_m)
    lines = []
    for ring in (polygon.exterior, *polygon.interiors):
        clipped = LineString(ring.coords).intersection(area)
        for part in getattr(clipped, "geoms", [clipped]):
            if isinstance(part, LineString) and not part.is_empty:
                lines.append(np.asarray(part.coords))
    return lines


def land_extent(land: list[LandOutline], lo_m: np.ndarray, hi_m: np.ndarray,
                reach_m: float) -> tuple[np.ndarray, np.ndarray]:
    """The box (lo, hi) of x, y metres grown to hold the land within ``reach_m`` of it.

    A map framed on the tracks then shows the shore they pass, and not the whole of a large coast.
    """
    near = box(lo_m[0] - reach_m, lo_m[1] - reach_m, hi_m[0] + reach_m, hi_m[1] + reach_m)
    lo, hi = np.array(lo_m, dtype=float), np.array(hi_m, dtype=float)
    for outline in land:
        part = outline.polygon.intersection(near)
        if not part.is_empty:
            x0, y0, x1, y1 = part.bounds
            lo, hi = np.minimum(lo, (x0, y0)), np.maximum(hi, (x1, y1))
    return lo, hi
